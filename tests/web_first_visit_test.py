#!/usr/bin/env python3
"""A student's first visit to the site: Debian's headless chromium on SwiftShader, an empty cache,
a 20 Mbit/s link.

Each visit is a fresh browser profile (an empty cache, no kept edits) with DevTools' network
throttling (Network.emulateNetworkConditions: 20 Mbit/s down and up, 20 ms latency) that loads
lab 2 at 640x480 (index.html?stage=lighting&size=640x480). It counts the bytes transferred
before the first frame: every response's Network.loadingFinished encodedDataLength (the bytes
on the wire, headers and compression included), and what a response still under way had
received (Network.dataReceived). The site is served twice, and each count says by which:
  * the kit's server (tools/web/serve.py, as ./kit web --serve serves): gzip where the browser
    accepts it and it saves a tenth;
  * a plain static server (python's http.server): nothing compressed, the worst a host does.
The test asserts at most 3 MB (3,000,000 bytes) from each, and that the grader's references
(kit-web-references.zip) are not fetched before the first frame; then, on the kit's server,
that choosing a scene fetches that scene's zip and draws it, that "Check my lab" says it is
loading the references, fetches them (the witness that the count sees them) and gives lab 2's
checks, and that a scene the URL names is fetched before the first frame, which draws it. It reports the time to the first frame and asserts nothing of it: time is measured by
the benchmark, --runs N (rounds of first visits in turn: from each server over the link, and
from the kit's server unthrottled, the CPU's share; the medians of N rounds, with the load
average), whose figures docs/performance.md gives.

usage: web_first_visit_test.py SITE_DIR WORK_DIR [--runs N]
Builds nothing: without a site or chromium it fails, saying what to install or build.
"""
import argparse
import http.server
import os
import pathlib
import shutil
import statistics
import sys
import threading
import time

from web_test import KIT_ROOT, Chromium, load_page, site_problem

sys.path.insert(0, str(KIT_ROOT / "tools/web"))
import serve  # noqa: E402  (the kit's server, ./kit web --serve)

QUERY = "stage=lighting&size=640x480"
MAX_BYTES = 3_000_000
LINK = {"offline": False, "latency": 20, "downloadThroughput": 20e6 / 8, "uploadThroughput": 20e6 / 8}
REFERENCES = "kit-web-references.zip"
SCENE = "crowd"  # a scene in a zip of its own, chosen after the first frame
URL_SCENE = "sun"  # one named in the URL: fetched before the first frame


class QuietKit(serve.SiteHandler):
    def log_message(self, *args):
        pass


class QuietPlain(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm"}

    def log_message(self, *args):
        pass


SERVERS = [("the kit's server (tools/web/serve.py: gzip)", QuietKit),
           ("a plain static server (http.server: no compression)", QuietPlain)]


def requests(events):
    """url -> {"bytes", "finished", "order"} of the responses the events tell of, in order."""
    by_id, out = {}, {}
    for event in events:
        method, params = event["method"], event.get("params", {})
        if method == "Network.requestWillBeSent":
            by_id[params["requestId"]] = {"url": params["request"]["url"], "bytes": 0, "finished": False,
                                          "order": len(by_id)}
        elif params.get("requestId") in by_id:
            entry = by_id[params["requestId"]]
            if method == "Network.dataReceived":
                entry["bytes"] += params.get("encodedDataLength", 0)
            elif method == "Network.loadingFinished":
                entry["bytes"], entry["finished"] = params["encodedDataLength"], True
            elif method == "Network.loadingFailed":
                entry["finished"] = True
    for entry in by_id.values():
        out.setdefault(entry["url"], []).append(entry)
    return out


def named(found, name):
    return [e for url, entries in found.items() if url.split("?")[0].endswith("/" + name) for e in entries]


def first_visit(work, origin, throttle=True):
    """A fresh, throttled browser that has drawn its first frame: (chromium, report, requests)."""
    chromium = Chromium(str(work))
    chromium.events = []
    chromium.call("Network.enable")
    if throttle:
        chromium.call("Network.emulateNetworkConditions", **LINK)
    chromium.call("Page.navigate", url=f"{origin}/index.html?{QUERY}")
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        state = chromium.evaluate("document.body ? (document.body.dataset.kitState || '') : ''")
        if state:
            break
        time.sleep(0.02)
    else:
        chromium.close()
        raise SystemExit(f"web_first_visit_test: FAILED: no first frame after 120 s at {origin}")
    found = requests(chromium.events)
    report = chromium.evaluate("window.kitReport || {}")
    if state != "ready":
        chromium.close()
        raise SystemExit(f"web_first_visit_test: FAILED: the page reported {state}: {report.get('error')}")
    return chromium, report, found


def after_first_frame(chromium, origin, failures):
    """On the kit's server: a chosen scene is fetched and drawn; Check my lab fetches the references;
    a scene the URL names is fetched before the first frame."""
    def expect(ok, what, saw):
        print(f"{'ok' if ok else 'FAILED'}: {what}: {saw}")
        if not ok:
            failures.append(what)

    chromium.evaluate("(async () => { while (!(window.kitPage && kitPage.ready)) "
                      "await new Promise(r => setTimeout(r, 50)); })()")
    frames = chromium.evaluate("kitPage.frames")
    chromium.evaluate(f"(() => {{ const s = document.getElementById('scene'); s.value = {SCENE!r}; "
                      "s.dispatchEvent(new Event('change')); })()")
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not chromium.evaluate(f"kitPage.frames > {frames} || kitPage.errors > 0"):
        time.sleep(0.05)
    scene = chromium.evaluate("kitPage.ui.scene")
    fetched = named(requests(chromium.events), f"kit-web-scene-{SCENE}.zip")
    expect(scene == SCENE and fetched and fetched[0]["finished"] and chromium.evaluate("kitPage.errors") == 0,
           f"choosing the scene {SCENE} fetches its zip and draws it",
           f"scene {scene}, kit-web-scene-{SCENE}.zip {fetched[0]['bytes'] if fetched else 'NOT fetched'} bytes")

    chromium.evaluate("document.getElementById('check').click()")
    loading, deadline = "", time.monotonic() + 180
    while time.monotonic() < deadline and not chromium.evaluate("!!kitPage.lastCheck"):
        text = chromium.evaluate("document.getElementById('check-body').textContent")
        if "Loading the grader's references" in text:
            loading = text
        time.sleep(0.05)
    check = chromium.evaluate("kitPage.lastCheck") or {}
    found = requests(chromium.events)
    references = named(found, REFERENCES)
    # The witness: counted the same way, the visit's bytes with the references are over the limit.
    total = sum(e["bytes"] for entries in found.values() for e in entries)
    expect(bool(loading), "Check my lab says it is loading the references", loading or "(never shown)")
    expect(references and references[0]["finished"] and check.get("status") == "graded" and total > MAX_BYTES,
           "Check my lab fetches the references (the witness) and gives lab 2's checks",
           f"{REFERENCES} {references[0]['bytes'] if references else 'NOT fetched'} bytes, {total:,} bytes in all "
           f"(more than {MAX_BYTES:,}); check {check.get('status')}, {check.get('passed')} of {check.get('total')} pass")

    report, _, _ = load_page(chromium, f"{origin}/index.html?stage=lighting&scene={URL_SCENE}&size=64x48")
    fetched = named(requests(chromium.events), f"kit-web-scene-{URL_SCENE}.zip")
    expect(report.get("scene") == URL_SCENE and fetched,
           "a scene the URL names is fetched before the first frame, which draws it",
           f"first frame of the scene {report.get('scene')}; kit-web-scene-{URL_SCENE}.zip "
           f"{'fetched' if fetched else 'NOT fetched'}")


def visit_and_count(work, origin, label, failures, throttle=True):
    chromium, report, found = first_visit(work, origin, throttle)
    seconds = report["seconds_since_navigation"]
    total = sum(e["bytes"] for entries in found.values() for e in entries)
    early = named(found, REFERENCES)
    largest = sorted(((e["bytes"], url.rsplit("/", 1)[-1]) for url, entries in found.items() for e in entries),
                     reverse=True)[:4]
    ok = total <= MAX_BYTES and not early
    print(f"{'ok' if ok else 'FAILED'}: first visit from {label}: {total:,} bytes before the first frame (at most "
          f"{MAX_BYTES:,}), {sum(len(v) for v in found.values())} responses, the largest "
          f"{', '.join(f'{n} {b:,}' for b, n in largest)}; references {'FETCHED' if early else 'not fetched'}; "
          f"first frame {seconds:.2f} s after navigation, the program ready at {report['seconds_to_runtime']:.2f} s "
          "(reported, not asserted)")
    if not ok:
        failures.append(f"first visit from {label}: {total:,} bytes before the first frame"
                        + (", the references among them" if early else ""))
    return chromium, report, total


def benchmark(args, servers, failures):
    """--runs N: N rounds of first visits, in turn (so that all see the same load): from each server
    over the link, and from the kit's server with no throttling (the share of the CPU)."""
    visits = [(label, origin, True) for label, _, origin in servers] + \
             [(servers[0][0] + ", no throttling", servers[0][2], False)]
    figures = {label: [] for label, _, _ in visits}
    print(f"load average before: {os.getloadavg()[0]:.1f}")
    for _ in range(args.runs):
        for label, origin, throttle in visits:
            chromium, report, total = visit_and_count(args.work, origin, label, failures, throttle)
            chromium.close()
            figures[label].append((report["seconds_since_navigation"], report["seconds_to_runtime"], total))
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    for label, runs in figures.items():
        print(f"{label}: first frame median {statistics.median(r[0] for r in runs):.2f} s "
              f"({', '.join(f'{r[0]:.2f}' for r in runs)}), the program ready at "
              f"{statistics.median(r[1] for r in runs):.2f} s, {statistics.median(r[2] for r in runs):,.0f} bytes "
              f"before the frame, {len(runs)} first visits")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("site", type=pathlib.Path)
    parser.add_argument("work", type=pathlib.Path)
    parser.add_argument("--runs", type=int, default=0, help="the benchmark: N first visits on each server, medians")
    args = parser.parse_args()
    problem = site_problem(args.site, ("index.html", "kit-page.js", "kit-web.js", "kit-web.wasm", "kit-web.data",
                                       "kit-web-data.js", "kit-web-packages.json", REFERENCES))
    if problem:
        print(f"web_first_visit_test: FAILED: {problem}")
        return 1
    shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True)
    failures, servers = [], []
    for label, handler in SERVERS:
        httpd = serve.server(args.site, 0, handler)
        servers.append((label, httpd, f"http://127.0.0.1:{httpd.server_address[1]}"))
        threading.Thread(target=httpd.serve_forever, daemon=True).start()
    print(f"link: {LINK['downloadThroughput'] * 8 / 1e6:g} Mbit/s, {LINK['latency']} ms latency; lab 2 at 640x480")
    try:
        if args.runs:
            benchmark(args, servers, failures)
        else:
            for index, (label, _, origin) in enumerate(servers):
                chromium, _, _ = visit_and_count(args.work, origin, label, failures)
                try:
                    if index == 0:
                        after_first_frame(chromium, origin, failures)
                finally:
                    chromium.close()
    finally:
        for _, httpd, _ in servers:
            httpd.shutdown()
    for failure in failures:
        print("FAILED:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
