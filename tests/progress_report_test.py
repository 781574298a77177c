#!/usr/bin/python3
"""./kit progress-report end to end (tests/progress_report.cmake).

Uses only what a student copy has: the starters in labs/ of the labs this kit
can assemble (labs 1 and 2 in the instructor's kit; a student copy's own lab).
  1. those labs with a notes file: the PDF has a title, a page per lab and notes,
     page 2 shows images, the notes and the grades are in its text;
  2. a lab that does not compile: still a page, with the grader's message;
  3. no references (as in a student copy) and no notes file: a template is
     written and the PDF still comes out, with the student's render;
  4. an unwritable output: a clear error, exit status 1.
Run: progress_report_test.py KIT_GRADE KIT_RENDER WORK_DIR
"""
import json
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "progress_report.py")
# The grader's configuration: how many checks each lab has.
with open(os.path.join(ROOT, "tools", "grade", "grading.json"), encoding="utf-8") as grading_file:
    GRADING = json.load(grading_file)

NOTES = """# Week 3 progress

The G-buffer pass works in my head; the normal matrix is next.

- Wrote `gbuffer.vert` with the model matrix
- Still to do: the material channel
"""

failures = []


def gradable_labs():
    """(number, folder) of the labs in labs/ whose earlier labs' solutions are all
    present (kit::gradable_labs): 1 and 2 here, lab N alone in a copy for lab N."""
    solutions = os.path.join(ROOT, "solutions")
    released = {int(d.split("-")[0]) for d in os.listdir(solutions) if re.match(r"^\d+-", d)} \
        if os.path.isdir(solutions) else set()
    labs = []
    for folder in sorted(os.listdir(os.path.join(ROOT, "labs"))):
        if re.match(r"^\d+-", folder):
            n = int(folder.split("-")[0])
            if all(k in released for k in range(1, n)):
                labs.append((n, folder))
    return labs


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

    labs = gradable_labs()[:2]
    first, first_folder = labs[0]
    names = ",".join(str(n) for n, _ in labs)
    if references:
        # 1. The starters of the labs this kit can assemble.
        out = os.path.join(work, "report.pdf")
        run = report(kit_grade, kit_render, "--labs", names, "--notes", notes, "--out", out, "--student", "Test Student")
        check(run.returncode == 0, f"labs {names}: exit status 0")
        check(run.stdout.strip() == out, f"labs {names}: prints the PDF's path")
        with open(out, "rb") as f:
            check(f.read(5) == b"%PDF-", f"labs {names}: the file starts with %PDF")
        pages = 2 + len(labs)
        check(pdf_pages(out) == pages, f"labs {names}: {pages} pages (title, a page per lab, notes): {pdf_pages(out)}")
        colours, non_white = image_area_stats(page_png(out, 2, os.path.join(work, "page2")))
        check(colours > 500, f"page 2 (lab {first}): the image columns hold more than 500 colours: {colours}")
        check(non_white > 0.3, f"page 2 (lab {first}): more than 30 % of the image columns is not white: {non_white:.0%}")
        title = pdf_text(out, 1)
        expected_title = ["Progress report", "Test Student", "Kit version"]
        if first == 1:  # the starters of labs 1 and 2 score nothing
            expected_title += ["1 gbuffer, 2 lighting", "0 / 20"]
        for words in expected_title:
            check(words in title, f"title page: '{words}'")
        lab_page = pdf_text(out, 2)
        expected_lab = [f"Lab {first}: {first_folder.split('-', 1)[1]}", "Frame time:", "median of 5 frames"]
        if first == 1:
            lab1_checks = len(GRADING["labs"]["1"]["checks"])
            expected_lab += ["0 / 10", f"0 of {lab1_checks} checks passed", "default scene, normal", "failed"]
        for words in expected_lab:
            check(words in lab_page, f"lab {first} page: '{words}'")
        text = pdf_text(out, pages)
        for words in ["Week 3 progress", "the normal matrix is next", "gbuffer.vert", "Still to do: the material channel"]:
            check(words in text, f"notes page: '{words}'")
        check("\u2022" in text, "notes page: the bullet is drawn as a bullet")

        # 2. A lab that does not compile is included with the grader's message.
        broken = os.path.join(work, "broken-labs")
        shutil.copytree(os.path.join(ROOT, "labs", first_folder), os.path.join(broken, first_folder))
        broken_file = sorted(f for f in os.listdir(os.path.join(broken, first_folder)) if f.endswith(".frag"))[0]
        with open(os.path.join(broken, first_folder, broken_file), "a", encoding="utf-8") as f:
            f.write("\nthis is not GLSL\n")
        out = os.path.join(work, "broken.pdf")
        run = report(kit_grade, kit_render, "--labs-dir", broken, "--labs", str(first), "--notes", notes, "--out", out)
        check(run.returncode == 0, "compile error: exit status 0")
        check(os.path.exists(out) and pdf_pages(out) == 3, f"compile error: 3 pages (title, lab {first}, notes)")
        lab_page = pdf_text(out, 2) if os.path.exists(out) else ""
        check("compile error" in lab_page and broken_file in lab_page and "syntax error" in lab_page,
              "compile error: the lab page holds the grader's message")
    else:
        print("tools/grade/references/ is missing (a student copy): the graded runs are skipped")

    # 3. No references, no notes file: the template is written, the PDF still comes out.
    empty = os.path.join(work, "no-references")
    os.makedirs(empty)
    template = os.path.join(work, "new-notes", "progress-notes.md")
    out = os.path.join(work, "ungraded.pdf")
    run = report(kit_grade, kit_render, "--labs", str(first), "--references", empty, "--notes", template, "--out", out)
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
    run = report(kit_grade, kit_render, "--labs", str(first), "--notes", notes, "--out", os.path.join(blocker, "r.pdf"))
    check(run.returncode == 1 and "cannot write" in run.stderr, "unwritable output: exit 1 with 'cannot write'")
    # 5. No kit-grade.
    run = report(os.path.join(work, "no-kit-grade"), kit_render, "--labs", str(first), "--notes", notes,
                 "--out", os.path.join(work, "x.pdf"))
    check(run.returncode == 1 and "kit-grade is not built" in run.stderr, "no kit-grade: exit 1 naming it")

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
