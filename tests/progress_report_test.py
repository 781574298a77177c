#!/usr/bin/python3
"""./kit progress-report end to end (tests/progress_report.cmake).

Uses only what a student copy has: the starters in labs/ (labs 1 and 2; stage 2
is assembled on solutions/01-gbuffer, which every copy from lab 2 on holds).
  1. labs 1,2 with a notes file: the PDF has 4 pages (title, two labs, notes),
     page 2 shows images, the notes and the grades are in its text;
  2. a lab that does not compile: still a page, with the grader's message;
  3. no references (as in a student copy) and no notes file: a template is
     written and the PDF still comes out, with the student's render;
  4. an unwritable output: a clear error, exit status 1.
Run: progress_report_test.py KIT_GRADE KIT_RENDER WORK_DIR
"""
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "progress_report.py")

NOTES = """# Week 3 progress

The G-buffer pass works in my head; the normal matrix is next.

- Wrote `gbuffer.vert` with the model matrix
- Still to do: the material channel
"""

failures = []


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def tool(name):
    path = shutil.which(name)
    if not path:
        sys.exit(f"{name} not found: install poppler-utils (./kit setup installs it)")
    return path


def report(kit_grade, kit_render, *args):
    command = [sys.executable, SCRIPT, "--kit-grade", kit_grade, "--kit-render", kit_render, *args]
    run = subprocess.run(command, capture_output=True, text=True, timeout=300)
    print(f"$ progress_report.py {' '.join(args)}  -> exit {run.returncode}")
    sys.stdout.write(run.stderr)
    return run


def pdf_pages(path):
    out = subprocess.run([tool("pdfinfo"), path], capture_output=True, text=True, check=True).stdout
    return int(next(l.split()[1] for l in out.splitlines() if l.startswith("Pages:")))


def pdf_text(path, page=None):
    args = [tool("pdftotext"), "-layout"] + (["-f", str(page), "-l", str(page)] if page else []) + [path, "-"]
    return subprocess.run(args, capture_output=True, text=True, check=True).stdout


def page_png(path, page, out_prefix):
    subprocess.run([tool("pdftoppm"), "-f", str(page), "-l", str(page), "-r", "60", "-png", "-singlefile",
                    path, out_prefix], check=True)
    import matplotlib.image as mpimg  # numpy arrays, from Debian's python3-matplotlib
    return mpimg.imread(out_prefix + ".png")


def image_area_stats(pixels):
    """Distinct colours and non-white share in the image columns of a lab page
    (the right 62 % of the page, below the header)."""
    import numpy as np
    h, w = pixels.shape[:2]
    area = pixels[int(h * 0.17):int(h * 0.92), int(w * 0.37):int(w * 0.93), :3]
    rgb = np.round(area * 255).astype(np.uint32)
    codes = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
    non_white = float(np.mean(np.any(rgb < 245, axis=-1)))
    return len(np.unique(codes)), non_white


def main():
    kit_grade, kit_render, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    notes = os.path.join(work, "notes.md")
    with open(notes, "w", encoding="utf-8") as f:
        f.write(NOTES)
    references = os.path.exists(os.path.join(ROOT, "tools", "grade", "references", "manifest.json"))

    if references:
        # 1. The starters of labs 1 and 2.
        out = os.path.join(work, "report.pdf")
        run = report(kit_grade, kit_render, "--labs", "1,2", "--notes", notes, "--out", out, "--student", "Test Student")
        check(run.returncode == 0, "labs 1,2: exit status 0")
        check(run.stdout.strip() == out, "labs 1,2: prints the PDF's path")
        with open(out, "rb") as f:
            check(f.read(5) == b"%PDF-", "labs 1,2: the file starts with %PDF")
        check(pdf_pages(out) == 4, f"labs 1,2: 4 pages (title, lab 1, lab 2, notes): {pdf_pages(out)}")
        colours, non_white = image_area_stats(page_png(out, 2, os.path.join(work, "page2")))
        check(colours > 500, f"page 2 (lab 1): the image columns hold more than 500 colours: {colours}")
        check(non_white > 0.3, f"page 2 (lab 1): more than 30 % of the image columns is not white: {non_white:.0%}")
        title = pdf_text(out, 1)
        for words in ["Progress report", "Test Student", "1 gbuffer, 2 lighting", "0 / 20", "Kit version"]:
            check(words in title, f"title page: '{words}'")
        lab1 = pdf_text(out, 2)
        for words in ["Lab 1: gbuffer", "0 / 10", "0 of 7 checks passed", "default scene, normal", "failed",
                      "Frame time:", "median of 5 frames"]:
            check(words in lab1, f"lab 1 page: '{words}'")
        text = pdf_text(out, 4)
        for words in ["Week 3 progress", "the normal matrix is next", "gbuffer.vert", "Still to do: the material channel"]:
            check(words in text, f"notes page: '{words}'")
        check("\u2022" in text, "notes page: the bullet is drawn as a bullet")

        # 2. A lab that does not compile is included with the grader's message.
        broken = os.path.join(work, "broken-labs")
        shutil.copytree(os.path.join(ROOT, "labs", "01-gbuffer"), os.path.join(broken, "01-gbuffer"))
        with open(os.path.join(broken, "01-gbuffer", "gbuffer.frag"), "a", encoding="utf-8") as f:
            f.write("\nthis is not GLSL\n")
        out = os.path.join(work, "broken.pdf")
        run = report(kit_grade, kit_render, "--labs-dir", broken, "--notes", notes, "--out", out)
        check(run.returncode == 0, "compile error: exit status 0")
        check(os.path.exists(out) and pdf_pages(out) == 3, "compile error: 3 pages (title, lab 1, notes)")
        lab1 = pdf_text(out, 2) if os.path.exists(out) else ""
        check("compile error" in lab1 and "gbuffer.frag" in lab1 and "syntax error" in lab1,
              "compile error: the lab page holds the grader's message")
    else:
        print("tools/grade/references/ is missing (a student copy): the graded runs are skipped")

    # 3. No references, no notes file: the template is written, the PDF still comes out.
    empty = os.path.join(work, "no-references")
    os.makedirs(empty)
    template = os.path.join(work, "new-notes", "progress-notes.md")
    out = os.path.join(work, "ungraded.pdf")
    run = report(kit_grade, kit_render, "--labs", "1", "--references", empty, "--notes", template, "--out", out)
    check(run.returncode == 0, "no references: exit status 0")
    check(os.path.exists(template), "no notes: the template was written")
    check("template" in run.stderr, "no notes: the command says so")
    check(os.path.exists(out) and pdf_pages(out) == 3, "no references: 3 pages")
    text = pdf_text(out) if os.path.exists(out) else ""
    check("Not graded here" in text and "references" in text, "no references: the lab page says why it is not graded")
    check("Progress notes" in text, "no notes: the PDF holds the template")

    # 4. An output that cannot be written.
    blocker = os.path.join(work, "a-file")
    open(blocker, "w").close()
    run = report(kit_grade, kit_render, "--labs", "1", "--notes", notes, "--out", os.path.join(blocker, "r.pdf"))
    check(run.returncode == 1 and "cannot write" in run.stderr, "unwritable output: exit 1 with 'cannot write'")
    # 5. No kit-grade.
    run = report(os.path.join(work, "no-kit-grade"), kit_render, "--labs", "1", "--notes", notes,
                 "--out", os.path.join(work, "x.pdf"))
    check(run.returncode == 1 and "kit-grade is not built" in run.stderr, "no kit-grade: exit 1 naming it")

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
