#!/usr/bin/python3
"""The page's "Progress report" in Debian's headless chromium on SwiftShader, as a student
makes it: lab 1's solution typed into the editor (lab 2 and the rest left as the starters),
a name and Markdown notes typed into the report's section, "Make my progress report"
pressed, and the report the page opens printed to PDF (DevTools' Page.printToPDF, as the
browser's Save as PDF prints it). pdftotext of the PDF holds the name, the notes (their
Markdown rendered), and each lab's section with its score: lab 1's and lab 2's as kit-grade
gives them for the same files (lab 1 full, the starter of lab 2 less: the witness that the
score is the files' own). The page's HTML is the one layout ./kit progress-report fills:
the same fields filled by tools/progress/layout.py give the same document, and the notes
are rendered as layout.py renders them. The notes are
kept in this browser (a reload shows them) and are in Download my labs as progress-notes.md.

usage: web_report_test.py SITE_DIR KIT_GRADE WORK_DIR
Prints how long the page took to check and time every lab.
"""
import base64
import json
import pathlib
import re
import shutil
import subprocess
import sys
import time
import zipfile

from web_page_test import Page
from web_test import KIT_ROOT, Chromium, serve, site_problem

sys.path.insert(0, str(KIT_ROOT / "tools"))
from progress.layout import format_score, notes_html, render_html  # noqa: E402

NAME = "Ada Student"
# Typed into the notes' text area; the PDF must hold their words, the Markdown rendered.
NOTES = "# Week 5 notes\n\nThe **normal matrix** was the hard part.\n\n- Lab 1 done\n- Lab 2: the BRDF is next\n"
NOTES_WORDS = ["Week 5 notes", "The normal matrix was the hard part.", "Lab 1 done", "Lab 2: the BRDF is next"]
REPORT_TIMEOUT = 600  # seconds for the page to check and time every lab on SwiftShader


def wait_for_report(chromium, timeout):
    """kitPage.lastReport once the page has made it. While a lab is checked the page's thread is
    busy in kit-web, and an evaluation waits for it: minutes for one lab on a loaded machine."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        answer = chromium.call("Runtime.evaluate", timeout=max(1, deadline - time.monotonic()),
                               expression="kitPage.lastReport", returnByValue=True)
        if answer["result"].get("value"):
            return answer["result"]["value"]
        time.sleep(0.5)
    raise SystemExit(f"web_report_test: FAILED: no report after {timeout} s: "
                     f"{chromium.evaluate('document.getElementById(`report-status`).textContent')}")


def print_to_pdf(chromium, url, path):
    """The report's own tab printed by Page.printToPDF, its @page size and margins kept."""
    target = chromium.call("Target.createTarget", url=url)["targetId"]
    page_session = chromium.session
    chromium.session = chromium.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
    try:
        deadline = time.monotonic() + 60
        while chromium.evaluate("document.readyState") != "complete" or \
                not chromium.evaluate("[...document.images].every(i => i.complete)"):
            if time.monotonic() > deadline:
                raise SystemExit("web_report_test: FAILED: the report's tab did not load in 60 s")
            time.sleep(0.1)
        pdf = chromium.call("Page.printToPDF", timeout=120, printBackground=True, preferCSSPageSize=True)
        path.write_bytes(base64.b64decode(pdf["data"]))
    finally:
        chromium.call("Target.closeTarget", targetId=target)
        chromium.session = page_session


def pdf_text(path):
    return subprocess.run(["pdftotext", "-layout", str(path), "-"], capture_output=True, text=True, check=True).stdout


def grader_scores(kit_grade, labs_dir, out):
    """kit-grade's {lab: "score / max"} for labs 1 and 2 of labs_dir."""
    subprocess.run([kit_grade, str(labs_dir), "--labs", "1,2", "--out", str(out)], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, check=False)  # failed checks: its exit status says so
    labs = json.loads((out / "summary.json").read_text())["labs"]
    return {int(n): f"{format_score(e['score'])} / {format_score(e['max_score'])}" for n, e in labs.items()}


def main():
    if len(sys.argv) != 4:
        raise SystemExit(__doc__)
    site, kit_grade, work = pathlib.Path(sys.argv[1]), sys.argv[2], pathlib.Path(sys.argv[3])
    problem = site_problem(site, ("index.html", "kit-page.js", "kit-web.js", "kit-web.wasm", "kit-web.data"))
    if problem or not shutil.which("pdftotext"):
        print(f"web_report_test: FAILED: {problem or 'no pdftotext (./kit setup installs poppler-utils)'}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    # The files the page will hold: lab 1 solved, every other lab its starter.
    labs_dir = work / "labs"
    shutil.copytree(KIT_ROOT / "labs", labs_dir)
    solved = KIT_ROOT / "solutions" / "01-gbuffer"
    for f in solved.iterdir():
        shutil.copy(f, labs_dir / "01-gbuffer" / f.name)
    expected = grader_scores(kit_grade, labs_dir, work / "kit-grade")

    server, origin = serve(site)
    failures = []

    def expect(ok, what, saw):
        print(("ok: " if ok else "FAILED: ") + f"{what}: {saw}")
        failures.extend([] if ok else [what])

    chromium = Chromium(str(work))
    page = Page(chromium)
    try:
        chromium.call("Browser.setDownloadBehavior", behavior="deny")
        url = f"{origin}/index.html?stage=gbuffer&shaders=labs&size=320x240"
        page.load(url)
        # Lab 1's solution typed into its two files, as a student pastes their work.
        for f in sorted(solved.iterdir()):
            path = f"/kit/labs/01-gbuffer/{f.name}"
            page.open_tab(path)
            page.replace_text(f.read_text(encoding="utf-8"))
        # The name and the notes typed into the report's section.
        for field, text in (("student-name", NAME), ("notes", NOTES)):
            page.js(f"document.getElementById('{field}').focus()")
            chromium.call("Input.insertText", text=text)

        start = time.monotonic()
        page.js("document.getElementById('make-report').click()")
        report = wait_for_report(chromium, REPORT_TIMEOUT)
        seconds = time.monotonic() - start
        print(f"the page checked and timed {len(report['labs'])} labs in {seconds:.0f} s "
              f"(its own count: {report['seconds']:.0f} s)")
        scores = {lab["number"]: lab["score"] for lab in report["labs"]}
        expect(scores.get(1) == expected[1] and scores.get(2) == expected[2] and expected[1] != expected[2],
               "the page's scores of labs 1 and 2 are kit-grade's for the same files (lab 1 solved, lab 2 the starter)",
               f"page {scores}, kit-grade {expected}")

        # The same layout as the command line: layout.py's filling of the page's fields.
        fields = page.js("kitPage.lastReport.fields")
        expect(render_html(fields) == report["html"], "the page's report is report.mustache filled as layout.py fills it",
               f"{len(report['html'])} characters")
        expect(fields["notes_html"] == notes_html(NOTES), "the page renders the notes as ./kit progress-report does",
               json.dumps(fields["notes_html"][:60]))
        shown = page.js("document.getElementById('report-frame').contentDocument.querySelectorAll('section.lab').length")
        expect(shown == len(report["labs"]), "the page shows the report in its frame, to print", f"{shown} lab sections")

        pdf = work / "report.pdf"
        print_to_pdf(chromium, report["url"], pdf)
        text = pdf_text(pdf)
        plain = re.sub(r"\s+", " ", text)
        expect(pdf.read_bytes()[:5] == b"%PDF-" and "Progress report" in text and NAME in text,
               "the printed PDF has the title page with the name", f"{pdf.stat().st_size} bytes")
        for lab in report["labs"]:
            heading = re.search(rf"Lab {lab['number']}: {lab['stage']}\s+(\S+ / \S+|not graded)", text)
            expect(heading is not None and heading.group(1) == lab["score"],
                   f"the PDF's lab {lab['number']} section shows its score", heading.group(0) if heading else "none")
        missing = [w for w in NOTES_WORDS if w not in plain]
        expect(not missing and "**" not in text, "the PDF holds the notes, their Markdown rendered", missing or "all")

        # Kept like the lab files: a reload shows them, and Download my labs carries them.
        page.load(url)
        kept = page.js("document.getElementById('notes').value")
        expect(kept == NOTES, "the notes are kept across a reload", json.dumps(kept[:40]))
        archive = work / "labs.zip"
        page.download(archive, "labs.zip")
        with zipfile.ZipFile(archive) as z:
            names = z.namelist()
            zipped = z.read("progress-notes.md").decode() if "progress-notes.md" in names else ""
        expect(zipped == NOTES, "Download my labs holds progress-notes.md", f"{len(names)} files")
    finally:
        chromium.close()
        server.shutdown()
    if failures:
        print(f"web_report_test: {len(failures)} FAILED: {', '.join(failures)}")
        return 1
    print("web_report_test: all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
