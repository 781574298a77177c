#!/usr/bin/env python3
"""The browser build in a real browser: Debian's headless chromium on SwiftShader.

Serves the site (kit-web's build folder, or ./kit web's out/web) on 127.0.0.1, loads
index.html with kit-render's options in its URL, reads the canvas back, and compares it
with kit-render's PNG of the same stage, view and size (--solution) within a stated
tolerance (the kit's OBJ scene among them); a witness checks that another stage's image
does not pass. Then the page's check (kit-grade's comparison compiled to WebAssembly,
tools/web/page_check.h) of every lab: the solutions pass every check on SwiftShader, and
the starters get the verdict, check by check, and the likely mistake that kit-grade gives
them. Builds nothing: ctest runs it after ./kit test has built the site; without a site or
chromium it fails, saying what to install or build.

usage: web_test.py SITE_DIR KIT_RENDER KIT_GRADE WORK_DIR
Chromium is driven over the DevTools protocol on a pipe (--remote-debugging-pipe: fds
3 and 4, NUL-separated JSON), with python's standard library alone; PNGs are read by
png_rgb.py.
"""
import base64
import functools
import http.server
import json
import os
import pathlib
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

from png_rgb import read_png

KIT_ROOT = pathlib.Path(__file__).resolve().parents[1]

SIZE = (320, 240)
# The desktop build's scenes, which the site packs (tests/web.cmake sets it).
SCENES = pathlib.Path(os.environ.get("KIT_SCENE_DIR") or KIT_ROOT / "build/default/scenes")
# How close the browser's frame must be to kit-render's (8-bit RGB levels), measured on
# SwiftShader against llvmpipe (the numbers each case prints): rasterisation and float
# rounding differ between the two at some edges and in the last bit of shading.
MAX_MEAN_DIFFERENCE = 1.0      # mean over all channels of all pixels
MAX_FAR_PIXELS = 0.005         # share of pixels with a channel off by more than FAR_LEVELS
FAR_LEVELS = 16
CASES = [  # (URL query, kit-render arguments): each stage's final image, lab 1's albedo
    ("stage=gbuffer&view=albedo&size=320x240", ["--stage", "gbuffer", "--view", "albedo"]),
    ("stage=lighting&size=320x240", ["--stage", "lighting"]),
    ("stage=attenuation&size=320x240", ["--stage", "attenuation"]),
    ("stage=normalmap&size=320x240", ["--stage", "normalmap"]),
    ("stage=postprocess&size=320x240", ["--stage", "postprocess"]),
    # Lab 6 reads its environment from an OpenEXR file (the browser build's own reader).
    ("stage=ibl&size=320x240", ["--stage", "ibl"]),
    ("stage=lightvolumes&size=320x240", ["--stage", "lightvolumes"]),
    # The kit's OBJ scene (its .mtl, a colour and a normal texture), read by the same loader.
    ("stage=normalmap&scene=/kit/scenes/obj-cube/obj-cube.obj&size=320x240",
     ["--stage", "normalmap", "--scene", str(SCENES / "obj-cube/obj-cube.obj")]),
]
LABS = range(1, 8)
CHROMIUM_FLAGS = [
    "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--disable-gpu-sandbox", "--no-first-run", "--disable-background-networking", "--disable-component-update",
    "--disable-sync", "--remote-debugging-pipe",
]


def compare(browser_rgba, width, height, reference_rgb):
    """(mean difference, share of far pixels) between the canvas's RGBA and the PNG's RGB."""
    total, far = 0, 0
    for p in range(width * height):
        worst = 0
        for c in range(3):
            d = abs(browser_rgba[p * 4 + c] - reference_rgb[p * 3 + c])
            total += d
            worst = max(worst, d)
        far += worst > FAR_LEVELS
    return total / (width * height * 3), far / (width * height)


class Chromium:
    """A headless chromium spoken to over --remote-debugging-pipe, one page attached."""

    def __init__(self, work):
        self.to_chrome_r, self.to_chrome_w = os.pipe()
        self.from_chrome_r, self.from_chrome_w = os.pipe()
        profile = tempfile.mkdtemp(prefix="profile-", dir=work)

        # Chromium reads commands on fd 3 and answers on fd 4: bash puts the pipes there (dash
        # takes one-digit descriptors only, and a second browser of one process gets higher ones)
        # (subprocess closes every descriptor it is not told to pass, after any preexec_fn).
        redirect = f'exec "$@" 3<&{self.to_chrome_r} 4>&{self.from_chrome_w}'
        self.process = subprocess.Popen(
            ["/bin/bash", "-c", redirect, "bash", "chromium", *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "about:blank"],
            pass_fds=(self.to_chrome_r, self.from_chrome_w),
            stdout=subprocess.DEVNULL, stderr=open(os.path.join(work, "chromium.log"), "wb"))
        os.close(self.to_chrome_r)
        os.close(self.from_chrome_w)
        self.buffer, self.next_id, self.session = b"", 0, None
        self.events = None  # a list: the DevTools events (those of the domains enabled) go in it
        targets = self.call("Target.getTargets")["targetInfos"]
        self.target = next(t for t in targets if t["type"] == "page")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=self.target, flatten=True)["sessionId"]

    def new_tab(self):
        """A new tab in place of this one (crashed, say), spoken to from now on; the old one closed."""
        old = self.target
        self.target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=self.target, flatten=True)["sessionId"]
        try:
            self.call("Target.closeTarget", timeout=10, targetId=old)
        except SystemExit:
            pass

    def call(self, method, timeout=60, **params):
        self.send(method, **params)
        deadline = time.monotonic() + timeout
        while True:
            while b"\0" not in self.buffer:
                left = deadline - time.monotonic()
                if left <= 0 or not select.select([self.from_chrome_r], [], [], left)[0]:
                    raise SystemExit(f"chromium did not answer {method} in {timeout} s")
                chunk = os.read(self.from_chrome_r, 1 << 20)
                if not chunk:
                    raise SystemExit(f"chromium closed its pipe during {method} (see chromium.log)")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            answer = json.loads(raw)
            if "method" in answer and self.events is not None:
                self.events.append(answer)
            elif answer.get("id") == self.next_id:
                if "error" in answer:
                    raise SystemExit(f"{method}: {answer['error']}")
                return answer["result"]

    def send(self, method, **params):
        """A command whose answer is not waited for (call() skips it when it comes)."""
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params}
        if self.session and not method.startswith("Target."):
            message["sessionId"] = self.session
        os.write(self.to_chrome_w, json.dumps(message).encode() + b"\0")

    def kill_renderers(self):
        """Ends this browser's renderer processes (its tabs crash), as "Exit page" ends a tab that
        stopped answering. Other browsers' are left alone: only processes descended from this one."""
        parents, commands = {}, {}
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open(f"/proc/{entry}/stat", "rb") as f:
                    parents[int(entry)] = int(f.read().rsplit(b")", 1)[1].split()[1])
                with open(f"/proc/{entry}/cmdline", "rb") as f:
                    commands[int(entry)] = f.read()
            except (OSError, IndexError, ValueError):
                continue
        def descends(pid):
            while pid in parents and pid > 1:
                if pid == self.process.pid:
                    return True
                pid = parents[pid]
            return False
        killed = [pid for pid, command in commands.items() if b"--type=renderer" in command and descends(pid)]
        for pid in killed:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        # Gone, and a moment for the browser to see it: a tab opened at once can be given the
        # spare renderer it has not yet found dead, and never answers.
        deadline = time.monotonic() + 10
        while any(os.path.exists(f"/proc/{pid}") for pid in killed) and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1)
        return killed

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise SystemExit(f"{expression[:60]}...: {result['exceptionDetails']}")
        return result["result"].get("value")

    def close(self):
        try:
            self.call("Browser.close", timeout=10)
        except SystemExit:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


# The canvas's pixels as the page shows them: drawn into a 2D canvas and read there,
# rows top-down, RGBA, base64.
READ_CANVAS = """(() => {
  const source = document.getElementById("canvas");
  const copy = document.createElement("canvas");
  copy.width = source.width; copy.height = source.height;
  const context = copy.getContext("2d");
  context.drawImage(source, 0, 0);
  const bytes = context.getImageData(0, 0, copy.width, copy.height).data;
  let text = "";
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return {width: copy.width, height: copy.height, rgba: btoa(text)};
})()"""


def load_page(chromium, url, timeout=120):
    """The page's report and canvas once kit-web has drawn (or refused) its frame."""
    start = time.monotonic()
    chromium.call("Page.navigate", url=url)
    while time.monotonic() - start < timeout:
        state = chromium.evaluate("document.body ? (document.body.dataset.kitState || '') : ''")
        if state:
            report = chromium.evaluate("window.kitReport || null")
            if state != "ready":
                raise SystemExit(f"{url}: kit-web reported {state}: {json.dumps(report)}")
            canvas = chromium.evaluate(READ_CANVAS)
            return report, canvas, time.monotonic() - start
        time.sleep(0.05)
    raise SystemExit(f"{url}: no frame after {timeout} s")


def site_problem(site, needed):
    """Why a browser test cannot run on `site` (files it lacks, no chromium), or None."""
    missing = [name for name in needed if not (site / name).is_file()]
    if missing:
        return f"{site} has no {', '.join(missing)} (./kit test and ./kit web build the site)"
    if not shutil.which("chromium"):
        return "no chromium (./kit test and ./kit web install it: Debian's chromium)"
    return None


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def serve(directory):
    """A static server of directory on 127.0.0.1 (a free port) in a thread: (server, origin)."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(QuietHandler, directory=str(directory)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}"


def load_check_files(chromium, lab):
    """What the page fetches at the first check of lab `lab`: the grader's references and the
    scenes its checks render, which kit-web.data leaves out (tools/web/site_files.py)."""
    chromium.evaluate("(async () => { while (!(window.kitPage && kitPage.ready)) await new Promise(r => setTimeout(r, 50)); "
                      f"return kitPage.loadCheckFiles({int(lab)}); }})()")


def kit_call(chromium, command):
    """The page's kit_call(command) (tools/web/kit_web.cpp), its answer as a dict."""
    text = json.dumps(json.dumps(command))
    return chromium.evaluate(f"JSON.parse(Module.ccall('kit_call', 'string', ['string'], [{text}]))")


def check_labs(chromium, kit_grade, work, failures):
    """The page's check of each lab: the solutions pass everything and their probed functions agree;
    the starters (labs/) get kit-grade's verdict on every check and function and the same first likely
    mistake."""
    graded = work / "kit-grade-starters"
    # The starters fail checks: kit-grade's exit status says so, and is not the test's.
    subprocess.run([kit_grade, str(KIT_ROOT / "labs"), "--out", str(graded)], stdout=subprocess.DEVNULL, check=False)
    expected = json.loads((graded / "summary.json").read_text())["labs"]
    for lab in LABS:
        load_check_files(chromium, lab)
        start = time.monotonic()
        solution = kit_call(chromium, {"cmd": "check", "lab": lab, "solution": True})
        seconds = time.monotonic() - start
        failed = [c["key"] for c in solution.get("checks", []) if not c["passed"]]
        print(f"page check, lab {lab} solution: {solution.get('status')}, {solution.get('passed')}/{solution.get('total')} "
              f"checks in {seconds:.1f} s{'; failed: ' + ', '.join(failed) if failed else ''}")
        if solution.get("status") != "graded" or failed or solution.get("passed") != len(expected[str(lab)]["checks"]):
            failures.append(f"page check of lab {lab}'s solution: {solution.get('error') or solution.get('message') or failed}")
        # The function probes on SwiftShader: the solution's agree everywhere.
        differing = [f["message"] for f in solution.get("functions", []) if f.get("status") != "agrees"]
        if differing:
            failures.append(f"page check of lab {lab}'s solution: its functions do not agree: {differing}")
        starter = kit_call(chromium, {"cmd": "check", "lab": lab})
        page = {c["key"]: c["passed"] for c in starter.get("checks", [])}
        grader = {key: c["passed"] for key, c in expected[str(lab)]["checks"].items()}
        page_first = (starter.get("likely_mistakes") or [{}])[0].get("id")
        grader_first = (expected[str(lab)].get("likely_mistakes") or [{}])[0].get("id")
        page_functions = {f["id"]: f["status"] for f in starter.get("functions", [])}
        grader_functions = {f["id"]: f["status"] for f in expected[str(lab)].get("functions", [])}
        agree = page == grader and page_first == grader_first and page_functions == grader_functions
        print(f"page check, lab {lab} starter: {sum(page.values())}/{len(page)} checks, likely {page_first}; kit-grade "
              f"{sum(grader.values())}/{len(grader)}, likely {grader_first}: {'same' if agree else 'DIFFERENT'}")
        if not agree:
            failures.append(f"page check of lab {lab}'s starter: {page} {page_first} {page_functions} against kit-grade's "
                            f"{grader} {grader_first} {grader_functions}")


def student_site(chromium, server_root, port, work, failures):
    """./kit web --student-copy 3: a site without lab 3's solution or later ones, which the
    page loads; witness: the kit's own site fails the same leak check."""
    site = work / "site-lab3"
    run = subprocess.run([str(KIT_ROOT / "kit"), "web", "--student-copy", "3", "--out", str(site)],
                         capture_output=True, text=True)
    print(f"./kit web --student-copy 3: exit {run.returncode}: {run.stderr.strip().splitlines()[-2:]}")
    if run.returncode != 0:
        failures.append("./kit web --student-copy 3 failed: " + run.stderr[-2000:])
        return
    extracted = work / "site-lab3-files"
    subprocess.run([sys.executable, str(KIT_ROOT / "tools/web/site_files.py"), "extract", str(site), str(extracted)],
                   check=True, stdout=subprocess.DEVNULL)
    folders = sorted(p.name for p in (extracted / "solutions").iterdir()) if (extracted / "solutions").is_dir() else []
    print(f"student site for lab 3: solutions of {folders}")
    if folders != ["01-gbuffer", "02-lighting"]:
        failures.append(f"the lab 3 site packs the solutions {folders}, not labs 1 and 2's")
    # The page runs from it: lab 3 from the student's starter, lab 2 from the released solution.
    shutil.copytree(site, server_root / "site-lab3")
    base = f"http://127.0.0.1:{port}/site-lab3/index.html?"
    load_page(chromium, base + "stage=lighting&size=64x48")
    load_check_files(chromium, 3)
    answer = kit_call(chromium, {"cmd": "check", "lab": 3, "solution": True})
    # The site has no solutions/03-attenuation: what renders is the starter (stage_library's
    # fallback), which passes none of lab 3's checks.
    print(f"student site, lab 3's solution asked for: {answer.get('status')}, {answer.get('passed')}/"
          f"{answer.get('total')} checks (must not pass)")
    if answer.get("passed"):
        failures.append("the lab 3 site passed lab 3's checks with its 'solution': it holds one")
    # Witness: the kit's own site (every solution) fails the leak check a student site passes.
    own = work / "own-site-files"
    subprocess.run([sys.executable, str(KIT_ROOT / "tools/web/site_files.py"), "extract", str(server_root), str(own)],
                   check=True, stdout=subprocess.DEVNULL)
    leak = subprocess.run([sys.executable, str(KIT_ROOT / "instructor/student_copy/leak_check.py"), str(own), "3",
                           "--kit", str(KIT_ROOT)], capture_output=True, text=True)
    print(f"witness: the kit's own site under the lab 3 leak check: exit {leak.returncode} (must fail)")
    if leak.returncode == 0:
        failures.append("witness: the kit's own site passed the lab 3 leak check: the check sees nothing")


def main():
    if len(sys.argv) != 5:
        raise SystemExit(__doc__)
    site, kit_render, kit_grade, work = (pathlib.Path(sys.argv[1]), sys.argv[2], sys.argv[3],
                                         pathlib.Path(sys.argv[4]))
    problem = site_problem(site, ("index.html", "kit-web.js", "kit-web.wasm", "kit-web.data", "kit-web-data.js",
                                  "kit-web-packages.json"))
    if problem:
        print(f"web_test: FAILED: {problem}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    # A copy of the site is served, so the student site can be served beside it.
    served = work / "site"
    shutil.copytree(site, served, ignore=shutil.ignore_patterns("CMakeFiles", "*.a", "*.cmake", "page-npm"))
    handler = functools.partial(Quiet, directory=str(served))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)  # a free port, this machine only
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/index.html?"

    references = {}
    for query, args in CASES:
        out = work / (query.replace("&", "_").replace("=", "-").replace("/", "-") + ".png")
        size = f"{SIZE[0]}x{SIZE[1]}"
        subprocess.run([kit_render, *args, "--solution", "--size", size, "--out", str(out)], check=True,
                       stdout=subprocess.DEVNULL)
        references[query] = read_png(out)

    chromium = Chromium(str(work))
    failures = []
    try:
        frames = {}
        for query, _ in CASES:
            report, canvas, seconds = load_page(chromium, base + query)
            rgba = base64.b64decode(canvas["rgba"])
            width, height, rgb = references[query]
            if (canvas["width"], canvas["height"]) != (width, height):
                failures.append(f"{query}: canvas is {canvas['width']}x{canvas['height']}, kit-render's {width}x{height}")
                continue
            mean, far = compare(rgba, width, height, rgb)
            frames[query] = rgba
            ok = mean <= MAX_MEAN_DIFFERENCE and far <= MAX_FAR_PIXELS
            print(f"{query}: mean difference {mean:.3f} levels (at most {MAX_MEAN_DIFFERENCE}), {100 * far:.2f}% of "
                  f"pixels off by more than {FAR_LEVELS} (at most {100 * MAX_FAR_PIXELS:.1f}%): "
                  f"{'ok' if ok else 'FAILED'}; page to frame {seconds:.2f} s; features {json.dumps(report.get('features'))}")
            if not ok:
                failures.append(f"{query}: the browser's frame differs from kit-render's")
        # Witness: each case's browser frame against the other case's reference fails the tolerance.
        (qa, _), (qb, _) = CASES[:2]
        if qa in frames:
            width, height, rgb = references[qb]
            mean, far = compare(frames[qa], width, height, rgb)
            print(f"witness: {qa} against {qb}'s reference: mean {mean:.3f}, {100 * far:.2f}% far (must fail)")
            if mean <= MAX_MEAN_DIFFERENCE and far <= MAX_FAR_PIXELS:
                failures.append("witness: two different stages' images pass the tolerance: the comparison sees nothing")
        load_page(chromium, base + "stage=gbuffer&size=64x48")
        check_labs(chromium, kit_grade, work, failures)
        student_site(chromium, served, server.server_address[1], work, failures)
    finally:
        chromium.close()
        server.shutdown()
    for failure in failures:
        print("FAILED:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
