#!/usr/bin/env python3
"""The browser build's figures (docs/performance.md, The browser page): the site's size, the
time to its first frame, edit-to-frame latency for a lab 2 edit, and each stage's frame time at
640x480 in Debian's headless chromium on SwiftShader beside kit-render's on llvmpipe.

    web_figures.py SITE_DIR KIT_RENDER [--runs N]

Prints a Markdown table. Medians of N runs (default 5); frame times are medians of 10 frames
after 3 warm-up frames, each drawn and finished (glFinish), not shown, as kit-render --frames
--timings measures them. The machine is shared: compare within one run only.
"""
import argparse
import functools
import gzip
import json
import http.server
import pathlib
import statistics
import subprocess
import sys
import threading
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "tests"))
import web_test  # noqa: E402  (the Chromium driver, load_page and kit_call of the browser test)

STAGES = ["gbuffer", "lighting", "attenuation", "normalmap", "postprocess", "ibl", "lightvolumes"]
SITE_FILES = ("index.html", "kit-web.js", "kit-web.wasm", "kit-web.data", "kit-web-data.js")


def site_size(site):
    kinds = (".js", ".css", ".html", ".json", ".zip")  # the zips: the scenes and references fetched later
    files = [p for p in site.iterdir() if p.is_file() and (p.name in SITE_FILES or p.suffix in kinds)]
    raw = sum(p.stat().st_size for p in files)
    packed = sum(len(gzip.compress(p.read_bytes(), compresslevel=9)) for p in files)
    return raw, packed


def kit_render_frame_ms(kit_render, stage):
    run = subprocess.run([kit_render, "--solution", "--stage", stage, "--size", "640x480", "--frames", "13",
                          "--timings", "--out", "/tmp/web_figures.png"],
                         capture_output=True, text=True, check=True)
    line = next(l for l in run.stderr.splitlines() if l.startswith("frame ms:"))
    return statistics.median(float(v) for v in line.split()[2:][3:])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("site", type=pathlib.Path)
    parser.add_argument("kit_render")
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *a):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(args.site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/index.html?"
    work = pathlib.Path("/tmp/web_figures")
    work.mkdir(exist_ok=True)
    # A first visit: a fresh browser (profile, cache and all) for each run.
    first = []
    for _ in range(args.runs):
        fresh = web_test.Chromium(str(work))
        try:
            report, _, _ = web_test.load_page(fresh, base + "stage=lighting&size=640x480")
            first.append(report["page_seconds_to_frame"])
        finally:
            fresh.close()
    chromium = web_test.Chromium(str(work))
    try:
        web_test.load_page(chromium, base + "stage=lighting&size=640x480")
        # Lab 2: the student's brdf.glsl, edited (a new comment line each time, so the text and
        # the program change), written into the page's file system and compiled; then drawn.
        web_test.kit_call(chromium, {"cmd": "configure", "stage": "lighting", "solution": False})
        source = chromium.evaluate("Module.FS.readFile('/kit/labs/02-lighting/brdf.glsl', {encoding: 'utf8'})")
        edits = []
        for i in range(args.runs + 1):
            text = f"// edit {i}\n" + source
            start = time.monotonic()
            answer = chromium.evaluate(
                "(() => { Module.FS.writeFile('/kit/labs/02-lighting/brdf.glsl', " + json.dumps(text) +
                "); return JSON.parse(Module.ccall('kit_call', 'string', ['string'], ['{\"cmd\":\"reload\"}'])); })()")
            if "error" in answer:
                raise SystemExit(f"the edit did not compile: {answer['error']}")
            if i:  # the first reload also compiles what the configure left
                edits.append(time.monotonic() - start)
        stages = {}
        for stage in STAGES:
            web_test.kit_call(chromium, {"cmd": "configure", "stage": stage, "solution": True, "width": 640, "height": 480})
            ms = web_test.kit_call(chromium, {"cmd": "time", "frames": 13})["frame_ms"][3:]
            stages[stage] = (statistics.median(ms), kit_render_frame_ms(args.kit_render, stage))
    finally:
        chromium.close()
        server.shutdown()

    raw, packed = site_size(args.site)
    print(f"| site size (page, program, scenes, references) | {raw / 2**20:.1f} MiB, {packed / 2**20:.1f} MiB gzipped |")
    print(f"| first frame (a first visit: page load to lab 2 at 640x480), median of {args.runs} | {statistics.median(first):.2f} s |")
    print(f"| lab 2 edit to frame (write, compile, draw), median of {args.runs} | {1000 * statistics.median(edits):.0f} ms |")
    print()
    print("| stage | SwiftShader (Chromium) ms | llvmpipe (kit-render) ms | ratio |")
    print("|---|---:|---:|---:|")
    for stage, (web, native) in stages.items():
        print(f"| {stage} | {web:.1f} | {native:.1f} | {web / native:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
