#!/usr/bin/env python3
"""The students' page (tools/web/page/) in a real browser: Debian's headless chromium on SwiftShader.

Serves the site (kit-web's build folder, or ./kit web's out/web) on 127.0.0.1 as web_test.py
does, and the test's own files under /test-files/, and proves, one step after the other in one
browser profile:
  1. the page loads lab 2 with your files (shaders=labs), its editor open on the lab's files;
  2. typing a syntax error into labs/02-lighting/brdf.glsl puts a diagnostic at that line in
     the editor, and the canvas keeps its last frame;
  3. fixing the edit draws again: a frame other than the first (the fix reads the normals as
     albedo), the diagnostic gone;
  4. the edit survives a reload of the page: in the editor, and in the first frame drawn;
  5. a lost WebGL context (WEBGL_lose_context) shows the message, keeps the files and draws
     again once restored; lost right after an edit, the page waits for the next edit;
  6. a dropped .glb (written here from one of the kit's scenes, fetched by the page from the
     site) draws; a dropped .obj draws too (with its .mtl and textures: web_obj_test.py);
  7. "Download my labs" gives a zip that `unzip -l` lists as labs/NN-name/FILE, every lab file,
     with the edit in it;
  8. "Check my lab" shows lab 2's checks with their images, and says it is a preview, and
     names the starter's functions that differ with their inputs; with
     (11, last) with lab 2 done in the editor it passes every check, and kit-grade gives the
     zip the page downloads the same verdicts and score;
  9. "Open folder" reads the student's folder, saves edits into it and takes changes made
     there (a folder of the origin's private file system stands in for the picker's);
 10. without shaders=labs, the first frame is the reference solution where the site has it;
     a lab file whose macros expand exponentially is refused at its line before compiling, and
     a load that restored an edit and never drew its first frame makes the next one start
     without it, naming the file and keeping its text (a loop that never ends, and a tab
     ended while it draws: web_runaway_test.py).
Each step states what it saw; a witness shows where a comparison could pass for nothing.
Builds nothing: without a site or chromium it fails, saying what to install or build.

usage: web_page_test.py SITE_DIR SCENE_DIR KIT_GRADE WORK_DIR
SCENE_DIR: the desktop build's scenes (build/default/scenes), from which the .glb is written;
KIT_GRADE grades the zip the page downloads once lab 2 is done in it (step 8b).
"""
import base64
import functools
import http.server
import json
import pathlib
import shutil
import struct
import subprocess
import sys
import threading
import time

from web_test import KIT_ROOT, READ_CANVAS, Chromium, load_page, site_problem

URL_QUERY = "stage=lighting&scene=default&view=final&size=320x240&shaders=labs"
BRDF = "/kit/labs/02-lighting/brdf.glsl"
# The starter's `return albedo / KIT_PI;` (in cook_torrance): " oops" is typed before its ';'.
# Found in the starter, so that a course that changed lab 2 keeps a passing test.
ERROR_TEXT = "return albedo / KIT_PI;"
ERROR_LINE = next(n for n, line in enumerate((KIT_ROOT / "labs/02-lighting/brdf.glsl").read_text(encoding="utf-8")
                                             .splitlines(), 1) if ERROR_TEXT in line)
# The fix: the starter, and a line that makes the lighting pass read the normals as albedo
# (brdf.glsl is included before lighting.frag's main), so the frame visibly changes.
FIX_LINE = "#define u_gbuffer_albedo u_gbuffer_normal"
GLB_SCENE = "texturing"  # a scene with images: the .glb carries them in its binary chunk
# Frames that must match differ by less than this (mean of 8-bit levels); frames that must
# differ by more. The same render twice on SwiftShader is identical.
SAME, DIFFERENT = 0.5, 2.0


def gltf_to_glb(gltf_path):
    """A .glb holding the .gltf's JSON, its buffers and its images in one binary chunk."""
    folder = gltf_path.parent
    gltf = json.loads(gltf_path.read_text())
    blob = bytearray()

    def add(data):
        offset = len(blob)
        blob.extend(data)
        blob.extend(b"\0" * (-len(blob) % 4))
        return offset

    offsets = [add((folder / b["uri"]).read_bytes()) for b in gltf["buffers"]]
    for view in gltf.get("bufferViews", []):
        view["byteOffset"] = view.get("byteOffset", 0) + offsets[view["buffer"]]
        view["buffer"] = 0
    for image in gltf.get("images", []):
        if "uri" in image:
            uri = image.pop("uri")
            data = (folder / uri).read_bytes()
            gltf.setdefault("bufferViews", []).append({"buffer": 0, "byteOffset": add(data), "byteLength": len(data)})
            image["bufferView"] = len(gltf["bufferViews"]) - 1
            image["mimeType"] = "image/jpeg" if uri.lower().endswith((".jpg", ".jpeg")) else "image/png"
    gltf["buffers"] = [{"byteLength": len(blob)}]
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + bytes(blob)
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def mean_difference(a, b):
    if len(a) != len(b):
        return float("inf")
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a)


def serve(site, files):
    """The site, and the test's files under /test-files/, on 127.0.0.1 at a free port: (server, origin)."""

    class Handler(http.server.SimpleHTTPRequestHandler):
        def translate_path(self, path):
            if path.startswith("/test-files/"):
                return str(files / path[len("/test-files/"):].split("?")[0])
            return super().translate_path(path)

        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Handler, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}"


class Expectations:
    """expect(ok, what, saw): each step's line, ok or FAILED; the failed ones kept in .failures."""

    def __init__(self):
        self.failures = []

    def __call__(self, ok, what, saw):
        print(f"{'ok' if ok else 'FAILED'}: {what}: {saw}")
        if not ok:
            self.failures.append(what)

    def result(self, test, seconds):
        """The test's time and its failures printed; its exit status."""
        print(f"{test}: {seconds:.1f} s")
        for failure in self.failures:
            print("FAILED:", failure)
        return 1 if self.failures else 0


class Page:
    def __init__(self, chromium):
        self.chromium = chromium

    def js(self, expression):
        return self.chromium.evaluate(expression)

    def frame(self):
        canvas = self.js(READ_CANVAS)
        return canvas["width"], canvas["height"], base64.b64decode(canvas["rgba"])

    def wait(self, expression, what, timeout=30):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.js(expression)
            if value:
                return value
            time.sleep(0.05)
        raise SystemExit(f"web_page_test: FAILED: no {what} after {timeout} s; page messages: "
                         f"{json.dumps(self.js('window.kitPage ? kitPage.messages.slice(-3) : null'))}")

    def load(self, url):
        report, _, seconds = load_page(self.chromium, url)
        self.wait("window.kitPage && kitPage.ready", "page ready")
        return report, seconds

    def counters(self):
        return self.js("({frames: kitPage.frames, errors: kitPage.errors})")

    def last_message(self):
        return self.js("kitPage.messages.length ? kitPage.messages[kitPage.messages.length - 1] : ''")

    def open_tab(self, path):
        self.js(f"document.querySelector('[role=tab][data-path=\"{path}\"]').click()")
        return self.js("document.querySelector('[role=tab][aria-selected=true]').dataset.path")

    def editor_text(self):
        return self.js("kitPage.editor.view.state.doc.toString()")

    def replace_text(self, text):
        """The whole file replaced, as a paste over a selection would."""
        self.js(f"(() => {{ const v = kitPage.editor.view; v.focus(); "
                f"v.dispatch({{changes: {{from: 0, to: v.state.doc.length, insert: {json.dumps(text)}}}, "
                f"userEvent: 'input.paste'}}); }})()")

    def download(self, path, what):
        """Clicks "Download my labs" and writes the zip the page made (kitPage.lastDownload) to `path`."""
        self.js("kitPage.lastDownload = null; document.getElementById('download').click()")
        data = self.wait("kitPage.lastDownload && (() => { let s = ''; const b = kitPage.lastDownload.bytes; "
                         "for (let i = 0; i < b.length; i += 0x8000) s += String.fromCharCode.apply(null, "
                         "b.subarray(i, i + 0x8000)); return btoa(s); })()", what)
        path.write_bytes(base64.b64decode(data))

    def drop(self, url, name):
        """A DragEvent dropping a File made of the bytes at url onto the canvas."""
        self.js(f"""(async () => {{
          const bytes = await (await fetch({json.dumps(url)})).arrayBuffer();
          const data = new DataTransfer();
          data.items.add(new File([bytes], {json.dumps(name)}));
          document.getElementById("canvas").dispatchEvent(
            new DragEvent("drop", {{bubbles: true, cancelable: true, dataTransfer: data}}));
          return bytes.byteLength;
        }})()""")


def main():
    if len(sys.argv) != 5:
        raise SystemExit(__doc__)
    site, scenes, kit_grade, work = (pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3],
                                     pathlib.Path(sys.argv[4]))
    needed = ("index.html", "kit-page.js", "kit-page.css", "kit-web.js", "kit-web.wasm", "kit-web.data", "kit-web-data.js")
    problem = site_problem(site, needed)
    if problem:
        print(f"web_page_test: FAILED: {problem}")
        return 1
    if not shutil.which("unzip"):
        print("web_page_test: FAILED: no unzip (./kit setup installs it)")
        return 1
    gltf = scenes / GLB_SCENE / f"{GLB_SCENE}.gltf"
    if not gltf.is_file():
        print(f"web_page_test: FAILED: no {gltf} (build the desktop scenes: cmake --build build/default "
              "--target kit_scene_files)")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    files = work / "files"
    files.mkdir(parents=True)
    (files / f"{GLB_SCENE}.glb").write_bytes(gltf_to_glb(gltf))
    (files / "cube.obj").write_text("mtllib cube.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")

    server, origin = serve(site, files)
    start = time.monotonic()
    expect = Expectations()

    chromium = Chromium(str(work))
    page = Page(chromium)
    try:
        try:
            chromium.call("Browser.setDownloadBehavior", behavior="deny")
        except SystemExit:
            pass  # an older chromium: the download may land in its profile, which is the test's

        # 1. The page and its editor.
        report, seconds = page.load(f"{origin}/index.html?{URL_QUERY}")
        tabs = page.js("[...document.querySelectorAll('#tabs [role=tab]')].map(t => t.dataset.path)")
        has_editor = page.js("!!document.querySelector('#editor .cm-editor .cm-content')")
        width, height, frame0 = page.frame()
        expect(has_editor and tabs == ["/kit/labs/02-lighting/lighting.frag", BRDF] and report.get("shaders") == "/kit/labs"
               and (width, height) == (320, 240),
               "the page loads lab 2's files in its editor",
               f"{seconds:.1f} s, tabs {tabs}, shaders {report.get('shaders')}, canvas {width}x{height}")

        # 2. A syntax error typed into brdf.glsl: a diagnostic at its line; the frame stays.
        page.open_tab(BRDF)
        starter = page.editor_text()
        before = page.counters()
        page.js(f"(() => {{ const v = kitPage.editor.view; v.focus(); const line = v.state.doc.line({ERROR_LINE}); "
                f"v.dispatch({{selection: {{anchor: line.from + line.text.indexOf(';')}}}}); }})()")
        chromium.call("Input.insertText", text=" oops")
        page.wait(f"kitPage.errors > {before['errors']}", "compile error")
        diagnostics = page.js(f"kitPage.editor.diagnostics({json.dumps(BRDF)})")
        marked = page.js("[...document.querySelectorAll('#editor .cm-lintRange-error')].map(e => e.textContent)")
        gutter = page.js("document.querySelectorAll('#editor .cm-lint-marker-error').length")
        typed = page.js(f"kitPage.editor.view.state.doc.line({ERROR_LINE}).text")
        expect([d["line"] for d in diagnostics] == [ERROR_LINE] and "oops" in typed and marked and gutter == 1,
               f"the compile error shows in the editor at line {ERROR_LINE}",
               f"diagnostics {diagnostics}, line {ERROR_LINE} reads {typed.strip()!r}, marked {marked}, "
               f"{gutter} gutter marker")
        message = page.last_message()
        expect(f"brdf.glsl:{ERROR_LINE}" in message and "Does not compile" in message, "the message area names the error",
               message.splitlines()[0] if message else "(none)")
        _, _, frame_error = page.frame()
        expect(mean_difference(frame_error, frame0) == 0, "the canvas keeps its last frame after a failed compile",
               f"mean difference {mean_difference(frame_error, frame0):.3f} from the frame before")

        # 3. The fix draws again (a frame that differs: the witness that the canvas is read live).
        fixed = starter.rstrip("\n") + "\n" + FIX_LINE + "\n"
        before = page.counters()
        page.replace_text(fixed)
        page.wait(f"kitPage.frames > {before['frames']}", "frame after the fix")
        _, _, frame_fixed = page.frame()
        after = page.counters()
        cleared = page.js(f"kitPage.editor.diagnostics({json.dumps(BRDF)}).length")
        change = mean_difference(frame_fixed, frame0)
        expect(after["errors"] == before["errors"] and change > DIFFERENT and cleared == 0,
               "the fixed edit compiles and draws", f"mean difference {change:.2f} from the first frame (more than "
               f"{DIFFERENT}), {cleared} diagnostics left")

        # 4. The edit survives a reload: in the editor and in the first frame.
        url = page.js("location.href")
        page.load(url)
        page.open_tab(BRDF)
        kept = page.editor_text()
        _, _, frame_reloaded = page.frame()
        expect(kept == fixed and mean_difference(frame_reloaded, frame_fixed) < SAME,
               "the edit survives a reload of the page",
               f"editor {'holds the edit' if kept == fixed else 'lost it'} ({url[len(origin):]}); first frame "
               f"{mean_difference(frame_reloaded, frame_fixed):.3f} from the fixed frame, "
               f"{mean_difference(frame_reloaded, frame0):.2f} from the starter's")

        # 5. A lost context: the message, the files kept, a frame once restored.
        lose = "document.getElementById('canvas').getContext('webgl2').getExtension('WEBGL_lose_context')"
        before = page.counters()
        page.js(f"window.testLose = {lose}; testLose.loseContext()")
        page.wait("kitPage.messages.some(m => m.includes('GPU reset while drawing'))", "lost-context message")
        lost_message = page.last_message()
        _, _, frame_lost = page.frame()  # the witness: a lost context's canvas is blank
        page.js("testLose.restoreContext()")
        page.wait(f"kitPage.frames > {before['frames']}", "frame after the context came back")
        _, _, frame_back = page.frame()
        files_kept = page.js(f"kitPage.labs.text({json.dumps(BRDF)})") == fixed and page.editor_text() == fixed
        expect("a shader took too long" in lost_message and files_kept and mean_difference(frame_back, frame_fixed) < SAME
               and mean_difference(frame_lost, frame_fixed) > DIFFERENT,
               "a lost context shows the message and draws again with the files kept",
               f"{lost_message.split('.')[0]!r}; frame {mean_difference(frame_back, frame_fixed):.3f} from before "
               f"(while lost: {mean_difference(frame_lost, frame_fixed):.2f}); files {'kept' if files_kept else 'LOST'}")
        # Lost right after an edit: no frame by itself; the next edit draws.
        edited = fixed + "// the next try\n"
        before = page.counters()
        page.replace_text(edited)
        page.wait(f"kitPage.frames > {before['frames']}", "frame of the edit")
        page.js("testLose.loseContext()")
        page.wait(f"kitPage.messages.length && kitPage.messages.at(-1).includes('GPU reset')", "lost message")
        page.js("testLose.restoreContext()")
        page.wait("kitPage.messages.at(-1).includes('does not draw your last edit again')", "waiting message")
        frames_waiting = page.counters()["frames"]
        time.sleep(1.0)
        idle = page.counters()["frames"] == frames_waiting
        edited += "// and again\n"
        page.replace_text(edited)
        page.wait(f"kitPage.frames > {frames_waiting}", "frame of the next edit")
        _, _, frame_next = page.frame()
        expect(idle and mean_difference(frame_next, frame_fixed) < SAME,
               "lost right after an edit, the page waits for the next edit",
               f"{'no frame' if idle else 'a FRAME'} until the next edit, then one "
               f"{mean_difference(frame_next, frame_fixed):.3f} from before")

        # 6. A dropped .glb draws; a dropped .obj draws, its missing .mtl named.
        before = page.counters()
        page.drop(f"/test-files/{GLB_SCENE}.glb", f"{GLB_SCENE}.glb")
        page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']}", "frame of the model")
        _, _, frame_model = page.frame()
        scene = page.js("kitPage.ui.scene")
        expect(page.counters()["errors"] == before["errors"] and scene.startswith("/work/dropped/")
               and mean_difference(frame_model, frame_next) > DIFFERENT,
               "a dropped .glb draws", f"scene {scene}, {mean_difference(frame_model, frame_next):.2f} from the "
               f"default scene's frame; {page.last_message()!r}")
        before = page.counters()
        page.drop("/test-files/cube.obj", "cube.obj")
        page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']}", "frame of the .obj")
        _, _, frame_obj = page.frame()
        obj_scene = page.js("kitPage.ui.scene")
        expect(page.counters()["errors"] == before["errors"] and obj_scene.endswith("/cube.obj")
               and "mtllib 'cube.mtl': file not found" in page.last_message()
               and mean_difference(frame_obj, frame_next) > DIFFERENT,
               "a dropped .obj draws, the .mtl it names and lacks named",
               f"scene {obj_scene}, {mean_difference(frame_obj, frame_next):.2f} from the default scene's frame; "
               f"{page.last_message().splitlines()[1] if page.last_message().count(chr(10)) else page.last_message()!r}")

        # 7. Download my labs: a zip in the layout ./kit grade takes, with the edit.
        zip_path = work / "labs.zip"
        page.download(zip_path, "zip")
        listing = subprocess.run(["unzip", "-l", str(zip_path)], capture_output=True, text=True).stdout
        names = sorted(parts[-1] for parts in map(str.split, listing.splitlines()) if parts and parts[-1].startswith("labs/"))
        expected = sorted(p[len("/kit/"):] for p in page.js("kitPage.labs.paths()"))
        inside = subprocess.run(["unzip", "-p", str(zip_path), "labs/02-lighting/brdf.glsl"], capture_output=True,
                                text=True).stdout
        expect(names == expected and len(names) >= 14 and inside == edited and inside != starter,
               "Download my labs gives labs/NN-name/FILE for every lab file",
               f"unzip -l lists {len(names)} files ({names[0]} ... {names[-1]}); brdf.glsl "
               f"{'is the edit' if inside == edited else 'is NOT the edit'}")

        # 8. Check my lab: lab 2's checks, each with its images; a preview.
        page.js("document.getElementById('check').click()")
        check = page.wait("kitPage.lastCheck", "check", timeout=60)
        shown = page.js("document.querySelectorAll('#check-body .check').length")
        images = page.js("document.querySelectorAll('#check-body .check canvas').length")
        notice = page.js("document.querySelector('#check-results .notice').textContent")
        count = len(page.js("kitPage.ui.catalogue.checks['2']"))
        expect(check.get("status") == "graded" and shown == count == check.get("total") and images >= 2 * count
               and "preview" in notice and "./kit grade" in notice,
               "Check my lab shows lab 2's checks with their images",
               f"{check.get('status')}, {check.get('passed')} of {check.get('total')} pass, {shown} shown with "
               f"{images} images, mistakes {[m['id'] for m in check.get('likely_mistakes', [])][:2]}")
        # The starter's functions differ from the solution's (tools/grade/frames/function_probes.h): each
        # is named with its first inputs, as kit-grade's report names them.
        functions = page.js("[...document.querySelectorAll('#check-body li')].map(li => li.textContent)"
                            ".filter(t => t.startsWith('Your function'))")
        expect(any(f.startswith("Your function fresnel_schlick(v_dot_h = ") for f in functions) and
               len(functions) == len(check.get("functions_text", [])),
               "Check my lab names the lab's functions that differ, with their inputs",
               f"{len(functions)} lines, the first: {functions[:1]}")
        # A failed check's worst pixel is ringed on its difference image: the ring passes 6 pixels
        # beside the pixel the answer names.
        ring = page.js("(() => { const checks = kitPage.lastCheck.checks || [];"
                       " const i = checks.findIndex(c => c.worst); if (i < 0) return null;"
                       " const w = checks[i].worst;"
                       " const canvas = document.querySelectorAll('#check-body .check')[i]"
                       ".querySelector('canvas[aria-label^=\"difference\"]');"
                       " const dx = w.x + 6 < canvas.width ? 6 : -6;"
                       " const g = canvas.getContext('2d');"
                       " return [w.x, w.y, ...g.getImageData(w.x + dx, w.y, 1, 1).data,"
                       " ...g.getImageData(w.x, w.y, 1, 1).data]; })()")
        # Witness: the pixel itself, inside the ring, keeps the difference's colour.
        expect(ring is not None and list(ring[2:6]) == [0, 255, 0, 255] and list(ring[6:10]) != [0, 255, 0, 255],
               "Check my lab rings a failed check's worst pixel on its difference image",
               f"worst pixel, the ring's colour beside it and the pixel's own: {ring}")
        # And says what each light gives there in the reference (tools/grade/frames/light_shares.h), as
        # kit-grade's report does.
        worst = page.js("(kitPage.lastCheck.checks || []).map(c => c.worst_pixel || '').filter(t => t)")
        expect(bool(worst) and all("in the reference" in w for w in worst) and any("% of it" in w for w in worst),
               "Check my lab's worst pixels say what each light gives there in the reference",
               f"{len(worst)} worst pixels, the first: ...{worst[0][-160:] if worst else ''}")
        page.js("[...document.querySelectorAll('#check-body h3')].find(h => h.textContent === 'Your functions')"
                ".scrollIntoView()")
        shot = page.chromium.call("Page.captureScreenshot", format="png")
        (work / "check-my-lab.png").write_bytes(base64.b64decode(shot["data"]))

        # 9. Open folder: the page reads the student's folder, saves edits into it, and takes
        # changes made there. The folder is one in the origin's private file system, the same
        # FileSystemDirectoryHandle the picker gives, handed over in place of the picker.
        lighting = "/kit/labs/02-lighting/lighting.frag"
        lighting_starter = page.js(f"kitPage.labs.starter({json.dumps(lighting)})")
        from_folder, changed_outside = lighting_starter + "// from the folder\n", lighting_starter + "// changed outside\n"
        page.js(f"""(async () => {{
          const root = await navigator.storage.getDirectory();
          const kit = await root.getDirectoryHandle("kit", {{create: true}});
          const lab = await (await kit.getDirectoryHandle("labs", {{create: true}}))
                        .getDirectoryHandle("02-lighting", {{create: true}});
          window.testLab = lab;
          window.testWrite = async (name, text) => {{
            const stream = await (await lab.getFileHandle(name, {{create: true}})).createWritable();
            await stream.write(text);
            await stream.close();
          }};
          window.testRead = async (name) => {{
            try {{
              return await (await (await lab.getFileHandle(name)).getFile()).text();
            }} catch (e) {{
              return null;  // the page is writing it (a write replaces the file when it closes)
            }}
          }};
          await testWrite("brdf.glsl", {json.dumps(edited)});
          await testWrite("lighting.frag", {json.dumps(from_folder)});
          window.showDirectoryPicker = async () => kit;
        }})()""")
        button_shown = page.js("!document.getElementById('open-folder').hidden")
        page.js("document.getElementById('open-folder').click()")
        page.wait(f"kitPage.labs.text({json.dumps(lighting)}) === {json.dumps(from_folder)}", "folder's file read")
        saved = edited + "// saved into the folder\n"
        page.replace_text(saved)
        on_disk = page.wait(f"testRead('brdf.glsl').then(t => t === {json.dumps(saved)})", "edit saved to the folder")
        page.js(f"testWrite('lighting.frag', {json.dumps(changed_outside)})")
        taken = page.wait(f"kitPage.labs.text({json.dumps(lighting)}) === {json.dumps(changed_outside)}",
                          "change made in the folder", timeout=10)
        expect(button_shown and on_disk and taken, "Open folder reads the folder, saves edits into it, takes its changes",
               page.js("document.getElementById('folder-info').textContent"))

        # 10. Without shaders=labs the first frame is the solution (the site has every solution).
        report, _ = page.load(f"{origin}/index.html?stage=lighting&size=64x48")
        expect(report.get("shaders") == "/kit/solutions" and page.js("kitPage.ui.solution") is True,
               "without shaders=labs the page draws the reference solution",
               f"shaders {report.get('shaders')}")
        # 10b. A lab file whose macros double thirty times is refused at its line before any GL
        # compile (the tab answers, the frame stays), and a load that restored an edit and
        # never drew its first frame (as if that file had locked the tab) makes the next load
        # start without it, saying which file it held back and keeping its text.
        page.load(f"{origin}/index.html?{URL_QUERY}")
        page.open_tab(BRDF)
        brdf_starter = page.js(f"kitPage.labs.starter({json.dumps(BRDF)})")
        bomb = "".join(f"#define M{i} M{i - 1} M{i - 1}\n" for i in range(1, 31))
        bomb_text = brdf_starter.rstrip("\n") + "\n#define M0 x\n" + bomb + "float bomb() { return M30; }\n"
        bomb_line = bomb_text.count("\n")
        before = page.counters()
        started = time.monotonic()
        page.replace_text(bomb_text)
        page.wait(f"kitPage.errors > {before['errors']}", "the macro file refused")
        answered = time.monotonic() - started
        message = page.last_message()
        expect(f"brdf.glsl:{bomb_line}: M30 expands to more than 65536 tokens" in message and answered < 20,
               "a file whose macros expand exponentially is refused by line before compiling",
               f"{answered:.1f} s; {message.splitlines()[0] if message else '(none)'}")
        key = page.js("'kit-web:' + location.pathname.replace(/[^/]*$/, '') + ':'")
        held_edit = brdf_starter + "\n// the edit the last visit restored before it stopped answering\n"
        page.js(f"localStorage.setItem({json.dumps(key + BRDF)}, {json.dumps(held_edit)}); "
                f"localStorage.setItem({json.dumps(key + 'restoring')}, {json.dumps(json.dumps([BRDF]))})")
        page.load(f"{origin}/index.html?{URL_QUERY}")
        page.open_tab(BRDF)
        held_message = page.js("kitPage.messages.find(m => m.includes('stopped while drawing')) || ''")
        stored = page.js(f"[localStorage.getItem({json.dumps(key + BRDF)}), localStorage.getItem({json.dumps(key + 'held:' + BRDF)}),"
                         f" localStorage.getItem({json.dumps(key + 'restoring')})]")
        page.js("[...document.querySelectorAll('#messages button')].find(b => b.textContent.includes('held-back')).click()")
        shown = page.js("document.querySelector('#messages pre') ? document.querySelector('#messages pre').textContent : ''")
        expect("labs/02-lighting/brdf.glsl" in held_message and page.editor_text() == brdf_starter
               and stored == [None, held_edit, None] and "stopped answering" in shown,
               "a load that never drew its first frame is followed by one without its edit, which is kept",
               f"message {held_message[:90]!r}...; editor {'the starter' if page.editor_text() == brdf_starter else 'not the starter'}; "
               f"kept {'as held back' if stored[1] == held_edit else stored}; shown {'yes' if 'stopped answering' in shown else 'no'}")

        # 11. Lab 2 done in the page (the solution's files typed into the editor): the check
        # passes every check, and the zip the page downloads gets from kit-grade the score and
        # the verdicts the page showed. The starter's check of step 8 is the witness (it failed).
        # Last, and on a fresh load: an open folder would ask which text to keep.
        page.load(f"{origin}/index.html?{URL_QUERY}")
        for name in ("brdf.glsl", "lighting.frag"):
            page.open_tab(f"/kit/labs/02-lighting/{name}")
            before = page.counters()
            page.replace_text((KIT_ROOT / "solutions/02-lighting" / name).read_text(encoding="utf-8"))
            page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']}", f"frame of {name}")
        page.js("kitPage.lastCheck = null; document.getElementById('check').click()")
        done = page.wait("kitPage.lastCheck", "check of the finished lab", timeout=60)
        done_zip = work / "lab2-done.zip"
        page.download(done_zip, "zip of the finished lab")
        graded_dir = work / "lab2-done-graded"
        subprocess.run([kit_grade, str(done_zip), "--labs", "2", "--out", str(graded_dir)], stdout=subprocess.DEVNULL,
                       check=False)
        graded = json.loads((graded_dir / "summary.json").read_text())["labs"]["2"]
        page_verdicts = {c["key"]: c["passed"] for c in done.get("checks", [])}
        grader_verdicts = {key: c["passed"] for key, c in graded["checks"].items()}
        expect(done.get("passed") == done.get("total") and page_verdicts == grader_verdicts
               and abs(done.get("score", -1) - graded["score"]) < 1e-9 and check.get("passed", 0) < check.get("total", 0),
               "lab 2 done in the page: its check and kit-grade's grade of the downloaded zip agree",
               f"page {done.get('passed')}/{done.get('total')} checks, {done.get('score')} points; kit-grade "
               f"{sum(grader_verdicts.values())}/{len(grader_verdicts)}, {graded['score']} points; the starter's "
               f"check {check.get('passed')}/{check.get('total')}")

    finally:
        chromium.close()
        server.shutdown()
    return expect.result("web_page_test", time.monotonic() - start)


if __name__ == "__main__":
    sys.exit(main())
