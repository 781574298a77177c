#!/usr/bin/env python3
"""A shader that loops forever, in the students' page on SwiftShader (web_page_test.py's browser
helpers; tests/web.cmake labels it slow: each step draws seconds of SwiftShader).

  1. the loop kit-grade's CPU limit ends on the desktop (test_grade_sandbox), typed at the top of
     lab 2's lighting.frag at 1280x960: the frame is drawn and the page answers (every loop of
     the browser's shaders is cut at a budget, common/gl/loop_guard.h; without that, nothing
     ends such a draw on SwiftShader and the tab never answered again); a frame past the
     page's time limit (1 s) is reported and not drawn again by itself;
  2. the tab's renderer ended while the page draws such an edit (a student's "Exit page"): the
     next load starts without that edit, names its file and keeps its text.

usage: web_runaway_test.py SITE_DIR WORK_DIR
"""
import json
import pathlib
import shutil
import sys
import time

from web_page_test import URL_QUERY, Expectations, Page, serve
from web_test import Chromium, site_problem


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    site, work = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    problem = site_problem(site, ("index.html", "kit-page.js", "kit-web.js", "kit-web.wasm", "kit-web.data"))
    if problem:
        print(f"web_runaway_test: FAILED: {problem}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    (work / "files").mkdir(parents=True)
    server, origin = serve(site, work / "files")
    start = time.monotonic()
    expect = Expectations()
    chromium = Chromium(str(work))
    page = Page(chromium)
    try:
        # 1. A loop that never ends, drawn; a frame past the time limit held.
        lighting_file = "/kit/labs/02-lighting/lighting.frag"
        big = URL_QUERY.replace("size=320x240", "size=1280x960")
        page.load(f"{origin}/index.html?{big}")
        page.open_tab(lighting_file)
        key = page.js("'kit-web:' + location.pathname.replace(/[^/]*$/, '') + ':'")
        lighting_starter = page.js(f"kitPage.labs.starter({json.dumps(lighting_file)})")
        endless = lighting_starter.replace("void main() {", "void main() {\n    float x = 1.0;\n    while (x > 0.0) "
                                           "x += gl_FragCoord.x * (1.0 + abs(sin(x)));\n    if (x < 0.0) discard;", 1)
        before = page.counters()
        started = time.monotonic()
        page.replace_text(endless)
        page.js("kitPage.compileNow()")
        answered = time.monotonic() - started
        drawn_message = page.js("kitPage.messages.find(m => m.startsWith('Compiled and drawn')) || ''")
        seconds = float(drawn_message.split("(")[1].split(" ms")[0]) / 1000 if drawn_message else -1
        slow = page.js("kitPage.messages.some(m => m.includes(\"past the page's limit\"))")
        expect(page.counters()["frames"] == before["frames"] + 1 and seconds >= 0 and slow == (seconds > 1.0),
               "a loop that never ends draws a frame at 1280x960 and the page answers; a slow frame is held",
               f"answered after {answered:.1f} s, frame {seconds:.1f} s, held {'yes' if slow else 'no'}")
        # 2. The tab ended while kit-web draws such an edit: the next load starts without it.
        endless_b = endless.replace("abs(sin(x))", "abs(cos(x))")
        page.chromium.send("Runtime.evaluate", expression=f"(() => {{ const v = kitPage.editor.view; v.dispatch({{"
                           f"changes: {{from: 0, to: v.state.doc.length, insert: {json.dumps(endless_b)}}}, "
                           f"userEvent: 'input.paste'}}); kitPage.compileNow(); }})()")
        try:
            page.chromium.call("Runtime.evaluate", timeout=0.3, expression="1")  # queued behind the draw
            busy = False
        except SystemExit:
            busy = True
        killed = page.chromium.kill_renderers()
        page.chromium.new_tab()
        page.load(f"{origin}/index.html?{URL_QUERY}")
        page.open_tab(lighting_file)
        held_message = page.js("kitPage.messages.find(m => m.includes('stopped while drawing')) || ''")
        kept = page.js(f"localStorage.getItem({json.dumps(key + 'held:' + lighting_file)})")
        expect(busy and killed and "labs/02-lighting/lighting.frag" in held_message
               and page.editor_text() == lighting_starter and kept == endless_b,
               "a tab ended while an edit drew is followed by a load without that edit, which is kept",
               f"{'busy' if busy else 'answering (the draw was over: a faster machine?)'} when "
               f"{len(killed)} renderer(s) were ended; message {held_message[:70]!r}; editor "
               f"{'the starter' if page.editor_text() == lighting_starter else 'not the starter'}; "
               f"kept {'yes' if kept == endless_b else 'no'}")
    finally:
        chromium.close()
        server.shutdown()
    return expect.result("web_runaway_test", time.monotonic() - start)


if __name__ == "__main__":
    sys.exit(main())
