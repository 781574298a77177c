#!/usr/bin/env python3
"""The handout in the page, and the page's layout, in headless chromium on SwiftShader.

The kit's site (kit-web's build folder) and a class's site built by ./kit web
--student-copy 2 are served side by side. As a student would:
  * a first visit loads no document and no KaTeX (witness: the pane, once opened, does);
  * the pane, opened from the keyboard (and open again on the next visit), shows lab 2's
    handout with its formulas typeset (KaTeX's markup, KaTeX's font loaded) and follows a
    change of lab;
  * a link to another document opens it at its section; a handout's "In the browser"
    address sets the controls to that view;
  * "Check my lab" on lab 2's starter names a likely mistake, and its "See
    handouts/02-lighting.md#common-mistakes" opens the pane at that section (witness: the
    pane was closed, and the section is far below the handout's top);
  * at 1280x720 no horizontal overflow with the frame, the editor and the handout each
    reachable (the handout in the editor's place); at 1920x1080 the three side by side; at
    768x1024 (a tablet) no overflow either. Screenshots are written to WORK_DIR, and the
    overflow measure has a witness (a too wide element is seen);
  * the class's site holds exactly its student copy's documents (no handouts/instructors.md)
    and none of the kit's instructors' sections, which the kit's own site shows (witness);
    the leak check reads the rendered HTML (witness: a solution line written as HTML, its
    < and & escaped, is found).

usage: web_handout_test.py SITE_DIR WORK_DIR
"""
import base64
import functools
import html
import http.server
import json
import pathlib
import re
import shutil
import subprocess
import sys
import threading
import time

from web_page_test import Page
from web_test import KIT_ROOT, Chromium, site_problem

sys.path.insert(0, str(KIT_ROOT / "instructor/student_copy"))
import leak_check  # noqa: E402  (the instructor's scripts, not a package)
import student_copy  # noqa: E402

LAB2 = "handouts/02-lighting.md"
QUERY = "stage=lighting&size=640x480&shaders=labs"
MIN_FRAGMENT = 25  # an instructors' section's plain text searched for in a rendered page

# The layout as the test measures it: the page's overflow, and each pane's box.
LAYOUT = """(() => {
  const box = (id) => {
    const e = document.getElementById(id), r = e.getBoundingClientRect();
    return {shown: r.width > 0 && r.height > 0, left: r.left, right: r.right, top: r.top, width: r.width};
  };
  return {scrollWidth: document.scrollingElement.scrollWidth, innerWidth: window.innerWidth,
          frame: box("frame-panel"), editor: box("editor-panel"), handout: box("handout-panel")};
})()"""


def text_of(html_text):
    """A rendered page's text, as leak_check.py reads it (tags gone, entities decoded)."""
    return " ".join(html.unescape(re.sub(r"<[^>]*>", " ", html_text)).split())


def instructors_fragments():
    """Plain-text runs of the kit's instructors' sections, per document."""
    out = {}
    for folder in ("handouts", "docs"):
        for md in sorted((KIT_ROOT / folder).glob("*.md")):
            text = md.read_text(encoding="utf-8")
            sections = student_copy._WHOLE_LINES.findall(text) + student_copy._INLINE.findall(text)
            plain = r"[A-Za-z0-9 ,.;:'()/_-]{%d,}" % MIN_FRAGMENT
            runs = [" ".join(r.split()) for s in sections for r in re.findall(plain, s)]
            if runs:
                out[f"{folder}/{md.name}"] = [r for r in runs if len(r) >= MIN_FRAGMENT]
    return out


class Test:
    def __init__(self, page, origin, work):
        self.page, self.origin, self.work, self.failures = page, origin, work, []

    def expect(self, ok, what, saw):
        print(f"{'ok' if ok else 'FAILED'}: {what}: {saw}")
        if not ok:
            self.failures.append(what)

    def js(self, expression):
        return self.page.js(expression)

    def viewport(self, width, height):
        self.page.chromium.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1,
                                mobile=False)
        time.sleep(0.3)

    def screenshot(self, name):
        shot = self.page.chromium.call("Page.captureScreenshot", format="png")
        (self.work / name).write_bytes(base64.b64decode(shot["data"]))
        metrics = self.page.chromium.call("Page.getLayoutMetrics")
        return metrics["cssContentSize"]["width"]

    def no_overflow(self, label, shot):
        layout = self.js(LAYOUT)
        content_width = self.screenshot(shot)
        self.expect(layout["scrollWidth"] <= layout["innerWidth"] and content_width <= layout["innerWidth"],
                    f"{label}: no horizontal overflow ({shot})",
                    f"scrollWidth {layout['scrollWidth']}, content {content_width}, window {layout['innerWidth']}")
        return layout

    def wait_handout(self, expected):
        return self.page.wait(f"document.body.dataset.handout === {json.dumps(expected)}", f"handout {expected}")

    def resources(self, part):
        return self.js("performance.getEntriesByType('resource').map(e => e.name)"
                       f".filter(n => n.includes({json.dumps(part)}))")


def first_visit_and_formulas(t):
    t.page.load(f"{t.origin}/own/index.html?{QUERY}")
    before = t.resources("/doc/") + t.resources("kit-doc.css")
    t.expect(before == [] and t.js("document.getElementById('handout-panel').hidden"),
             "a first visit loads no document and no KaTeX (the pane closed)", before)
    # Opened from the keyboard: the button focused, Enter.
    t.js("document.getElementById('handout-toggle').focus()")
    for kind in ("keyDown", "keyUp"):
        t.page.chromium.call("Input.dispatchKeyEvent", type=kind, key="Enter", code="Enter", windowsVirtualKeyCode=13,
                             text="\r" if kind == "keyDown" else "")
    t.wait_handout(f"{LAB2}#")
    after = t.resources("/doc/") + t.resources("kit-doc.css")
    t.expect(all(any(n.endswith(end) for n in after) for end in ("katex.min.css", "kit-doc.css", "02-lighting.html")),
             "witness: the opened pane loads KaTeX's style sheet, the documents' and the handout",
             [n.split("/")[-1] for n in after])
    t.expect(t.js("document.getElementById('handout-toggle').getAttribute('aria-expanded')") == "true",
             "the handout's button says it is expanded", "aria-expanded")
    math = t.js("""(() => {
      const body = document.getElementById('handout-body');
      return {katex: body.querySelectorAll('.katex .katex-html').length,
              mathml: body.querySelectorAll('.katex math annotation[encoding="application/x-tex"]').length,
              raw: (body.textContent.match(/\\$[^$\\s][^$]*\\$/g) || []).length,
              tex: (body.querySelector('.katex annotation') || {}).textContent || ''};
    })()""")
    t.page.wait("document.fonts.check('16px KaTeX_Main')", "KaTeX's font", timeout=20)
    t.expect(math["katex"] > 10 and math["mathml"] == math["katex"] and math["raw"] == 0,
             "lab 2's handout: its formulas typeset by KaTeX, no $...$ left as text, KaTeX's font loaded", math)


def links(t):
    # Following the lab: lab 1 chosen, its handout shown.
    t.js("(() => { const s = document.getElementById('stage'); s.value = 'gbuffer';"
         " s.dispatchEvent(new Event('change')); })()")
    t.wait_handout("handouts/01-gbuffer.md#")
    t.expect(True, "the pane follows the lab chosen", "lab 1 -> handouts/01-gbuffer.md")
    # A link to another document's section, in the pane.
    t.js("""(() => { const s = document.getElementById('handout-doc'); s.value = 'handouts/02-lighting.md';
                     s.dispatchEvent(new Event('change')); })()""")
    t.wait_handout(f"{LAB2}#")
    doc, section = t.js("""(() => {
      const a = [...document.querySelectorAll('#handout-body a[data-doc^="docs/"][data-anchor]')][0];
      a.click();
      return [a.dataset.doc, a.dataset.anchor];
    })()""")
    t.wait_handout(f"{doc}#{section}")
    t.expect(t.js(f"!!document.getElementById('doc:{section}')"), "a link to another document opens it at its section",
             f"{doc}#{section}")
    # The handout's "In the browser" address: the controls set to that view (from lab 1).
    t.js("(() => { const s = document.getElementById('stage'); s.value = 'gbuffer';"
         " s.dispatchEvent(new Event('change')); })()")
    t.js("document.getElementById('shaders-solution').click()")
    t.js(f"""(() => {{ const s = document.getElementById('handout-doc'); s.value = '{LAB2}';
                      s.dispatchEvent(new Event('change')); }})()""")
    t.wait_handout(f"{LAB2}#")
    before = t.js("[kitPage.ui.stage.name, kitPage.ui.solution]")
    href = t.js("(() => { const a = document.querySelector('#handout-body a[data-view]'); a.click();"
                " return a.dataset.view; })()")
    t.page.wait("kitPage.ui.stage.name === 'lighting' && location.search.includes('stage=lighting')", "lab 2 chosen")
    after = t.js("[kitPage.ui.stage.name, kitPage.ui.solution, location.search]")
    t.expect(before == ["gbuffer", True] and after[:2] == ["lighting", False] and "shaders=labs" in after[2],
             "a handout's view address sets the controls: lab 2, the student's files", f"{href}: {before} -> {after}")


def likely_mistake(t):
    t.js("document.getElementById('handout-close').click()")
    t.js("document.getElementById('check').click()")
    t.page.wait("!!document.querySelector('#check-body .see-handout a')", "the check's likely mistakes", timeout=240)
    mistakes = t.js("kitPage.lastCheck.likely_mistakes.map(m => m.id)")
    closed = t.js("document.getElementById('handout-panel').hidden")
    t.js("document.querySelector('#check-body .see-handout a').click()")
    t.wait_handout(f"{LAB2}#common-mistakes")
    where = t.js("""(() => {
      const body = document.getElementById('handout-body'), heading = document.getElementById('doc:common-mistakes');
      const b = body.getBoundingClientRect(), h = heading.getBoundingClientRect();
      return {scrollTop: body.scrollTop, offset: h.top - b.top, height: b.height,
              focused: document.activeElement === heading, text: heading.textContent};
    })()""")
    # The heading at the pane's top, to a pixel: scrolling rounds to device pixels, which leaves
    # the heading a fraction of one above the pane's edge at some layouts.
    t.expect(closed and where["scrollTop"] > 500 and -1 <= where["offset"] < where["height"] / 2 and where["focused"],
             "a likely mistake's 'See handouts/02-lighting.md#common-mistakes' opens the closed pane at that section, "
             "far below the handout's top", f"{mistakes}: {where}")


def layouts(t):
    t.viewport(1280, 720)
    t.js("document.getElementById('handout-close').click()")
    closed = t.no_overflow("1280x720, the editor shown", "page-1280x720-editor.png")
    t.js("document.getElementById('handout-toggle').click()")
    t.wait_handout(t.js("document.body.dataset.handout"))
    opened = t.no_overflow("1280x720, the handout shown", "page-1280x720-handout.png")
    t.expect(closed["frame"]["shown"] and closed["editor"]["shown"] and opened["frame"]["shown"] and
             opened["handout"]["shown"] and opened["handout"]["right"] <= 1280 and opened["handout"]["top"] < 720,
             "1280x720: the frame with the editor, and with the handout in its place (one click apart)",
             f"editor {closed['editor']}, handout {opened['handout']}")
    t.viewport(1920, 1080)
    wide = t.no_overflow("1920x1080", "page-1920x1080.png")
    panes = [wide["frame"], wide["editor"], wide["handout"]]
    side_by_side = all(p["shown"] and p["top"] < 1080 and p["width"] > 300 for p in panes) and \
        panes[0]["right"] <= panes[1]["left"] and panes[1]["right"] <= panes[2]["left"] and panes[2]["right"] <= 1920
    t.expect(side_by_side, "1920x1080: the frame, the editor and the handout side by side",
             [(round(p["left"]), round(p["right"])) for p in panes])
    t.viewport(768, 1024)
    tablet = t.no_overflow("768x1024 (a tablet)", "page-768x1024.png")
    t.expect(tablet["frame"]["shown"] and tablet["handout"]["shown"], "768x1024: the frame and the handout shown",
             f"frame {tablet['frame']['width']:.0f} px, handout {tablet['handout']['width']:.0f} px wide")
    # Witness: the measure sees a page wider than its window.
    t.js("document.body.append(Object.assign(document.createElement('div'),"
         " {id: 'too-wide', style: 'width: 2000px; height: 1px'}))")
    witness = t.js(LAYOUT)
    t.js("document.getElementById('too-wide').remove()")
    t.expect(witness["scrollWidth"] > witness["innerWidth"], "witness: an element 2000 px wide is seen as overflow",
             f"scrollWidth {witness['scrollWidth']}, window {witness['innerWidth']}")
    t.viewport(1280, 720)
    unlabelled = t.js("""[...document.querySelectorAll('header button, #handout-panel button, #handout-panel select')]
      .filter(e => !((e.labels && e.labels.length) || e.getAttribute('aria-label') || e.textContent.trim()))
      .map(e => e.id)""")
    t.expect(unlabelled == [], "the handout's controls have labels", unlabelled)


def student_site(t, root, site):
    run = subprocess.run([str(KIT_ROOT / "kit"), "web", "--student-copy", "2", "--out", str(root / "lab2")],
                         capture_output=True, text=True)
    t.expect(run.returncode == 0, "./kit web --student-copy 2 builds a class's site, its documents leak-checked",
             run.stderr.strip().splitlines()[-2:])
    if run.returncode != 0:
        return
    own_index = json.loads((site / "doc/index.json").read_text())["documents"]
    class_index = json.loads((root / "lab2/doc/index.json").read_text())["documents"]
    copy_docs = sorted(f"{folder}/{p.name}" for folder in ("handouts", "docs") for p in (KIT_ROOT / folder).glob("*.md")
                       if f"{folder}/{p.name}" not in student_copy.INSTRUCTOR_FILES)
    class_docs = sorted(d["path"] for d in class_index)
    t.expect(class_docs == copy_docs and "handouts/instructors.md" in [d["path"] for d in own_index],
             "the class's site holds its student copy's documents; the kit's own also instructors.md (witness)",
             f"{len(class_docs)} documents, the kit's {len(own_index)}")
    seen_own, seen_class = [], []
    for doc, runs in instructors_fragments().items():
        page = doc.replace(".md", ".html")
        own_text = text_of((site / "doc" / page).read_text(encoding="utf-8"))
        class_file = root / "lab2/doc" / page
        class_text = text_of(class_file.read_text(encoding="utf-8")) if class_file.is_file() else ""
        seen_own += [f"{doc}: {r}" for r in runs if r in own_text]
        seen_class += [f"{doc}: {r}" for r in runs if r in own_text and r in class_text]
    t.expect(len(seen_own) >= 10 and seen_class == [],
             "no instructors' section in the class's rendered documents; the kit's own show them (witness)",
             f"{len(seen_own)} passages in the kit's, {len(seen_class)} in the class's: {seen_class[:3]}")
    # In the browser: lab 2's handout on the class's site, without the instructors' test it
    # names. The pane was left open (on the same origin): the page opens it again by itself.
    t.page.load(f"{t.origin}/lab2/index.html?stage=lighting&size=320x240")
    t.wait_handout(f"{LAB2}#")
    t.expect(not t.js("document.getElementById('handout-panel').hidden"),
             "the pane left open is open again after a reload (a first visit's was closed)", "shown")
    shown = t.js("document.getElementById('handout-body').textContent")
    options = t.js("[...document.getElementById('handout-doc').options].map(o => o.value)")
    own_lab2 = text_of((site / "doc/handouts/02-lighting.html").read_text(encoding="utf-8"))
    t.expect("test_lighting_pass" not in shown and "test_lighting_pass" in own_lab2 and
             "handouts/instructors.md" not in options and len(options) == len(copy_docs),
             "the class's page shows lab 2's handout without its instructors' section, and no instructors' document",
             f"{len(shown)} characters, {len(options)} documents")
    # The leak check reads HTML as text. Witness: a lab 2 solution line in a page, escaped as HTML.
    line = next(text for _, text in leak_check.solution_lines(KIT_ROOT, 2) if re.search(r"[<>&]", text))
    planted = t.work / "planted"
    (planted / "doc").mkdir(parents=True, exist_ok=True)
    (planted / "doc/page.html").write_text(f"<pre><code>{html.escape(line)}\n</code></pre>\n", encoding="utf-8")
    leak = subprocess.run([sys.executable, str(KIT_ROOT / "instructor/student_copy/leak_check.py"), str(planted), "2",
                           "--kit", str(KIT_ROOT)], capture_output=True, text=True)
    t.expect(leak.returncode == 1 and "doc/page.html" in leak.stdout and html.escape(line) != line,
             "witness: the leak check finds a solution line written as HTML",
             f"{html.escape(line)}: exit {leak.returncode}")


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    site, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    problem = site_problem(site, ("index.html", "kit-page.js", "kit-web.js", "kit-web.wasm", "kit-web.data",
                                  "doc/index.json", "doc/katex/katex.min.css"))
    if problem:
        print(f"web_handout_test: FAILED: {problem}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    root = work / "served"
    root.mkdir(parents=True)
    (root / "own").symlink_to(site.resolve())

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(root)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    chromium = Chromium(str(work))
    t = Test(Page(chromium), f"http://127.0.0.1:{server.server_address[1]}", work)
    start = time.monotonic()
    try:
        t.viewport(1280, 720)
        first_visit_and_formulas(t)
        links(t)
        likely_mistake(t)
        layouts(t)
        student_site(t, root, site)
    finally:
        chromium.close()
        server.shutdown()
    print(f"web_handout_test: {len(t.failures)} failures in {time.monotonic() - start:.0f} s; screenshots in {work}")
    for failure in t.failures:
        print(f"  FAILED: {failure}")
    return 1 if t.failures else 0


if __name__ == "__main__":
    sys.exit(main())
