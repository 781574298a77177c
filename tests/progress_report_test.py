#!/usr/bin/python3
"""./kit progress-report end to end (tests/progress_report.cmake).

Uses only what a student copy has: the starters in labs/ of the labs this kit
can assemble (labs 1 and 2 in the instructor's kit; a student copy's own lab),
and for 6. the solutions/ it holds.
  1. those labs with a notes file: the PDF has a title page, each lab's section from
     a new page, and the notes last; page 2 shows images, the notes and the grades
     are in its text;
  2. a lab that does not compile: still a page, with the grader's message;
  3. no references (as in a student copy) and no notes file: a template is
     written and the PDF still comes out, with the student's render;
  4. an unwritable output: a clear error, exit status 1;
  5. no kit-grade: a clear error.
  6. No words drawn over words (pdftotext -bbox-layout's boxes): on every page of
     the PDFs above (the starters' checks fail) and of a report of every lab this
     kit can grade, with the solutions it has (passing checks, every lab's titles,
     each lab's score in its section); and the checker itself finds words that
     WeasyPrint is told to draw over each other.
Run: progress_report_test.py KIT_GRADE KIT_RENDER WORK_DIR
"""
import html
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


WORD = re.compile(r'<word xMin="([-\d.]+)" yMin="([-\d.]+)" xMax="([-\d.]+)" yMax="([-\d.]+)">(.*?)</word>', re.S)


def pdf_word_boxes(path):
    """[[(xMin, yMin, xMax, yMax, word), ...] per page] from pdftotext -bbox-layout (points, from the top)."""
    run = subprocess.run([tool("pdftotext"), "-bbox-layout", path, "-"], capture_output=True, text=True, check=True)
    pages = run.stdout.split("<page ")[1:]
    return [[(float(a), float(b), float(c), float(d), html.unescape(w)) for a, b, c, d, w in WORD.findall(p)]
            for p in pages]


def word_overlaps(path, epsilon=0.5):
    """Words drawn over other words: [(page, word, other word)], pages counted from 1. Two boxes
    overlap when they share more than epsilon points in both directions; a word drawn twice in
    the same place (fake bold, a shadow) is not text over text and is left out."""
    found = []
    for number, words in enumerate(pdf_word_boxes(path), 1):
        words.sort(key=lambda w: w[1])
        for i, a in enumerate(words):
            for b in words[i + 1:]:
                if b[1] >= a[3] - epsilon:
                    break  # sorted by yMin: no later word reaches up into a
                if min(a[2], b[2]) - max(a[0], b[0]) <= epsilon or min(a[3], b[3]) - max(a[1], b[1]) <= epsilon:
                    continue
                if a[4] == b[4] and all(abs(p - q) <= epsilon for p, q in zip(a[:4], b[:4])):
                    continue
                found.append((number, a[4], b[4]))
    return found


def page_png(path, page, out_prefix):
    subprocess.run([tool("pdftoppm"), "-f", str(page), "-l", str(page), "-r", "60", "-png", "-singlefile",
                    path, out_prefix], check=True)
    import matplotlib.image as mpimg  # numpy arrays, from Debian's python3-matplotlib
    return mpimg.imread(out_prefix + ".png")


def overlap_witness(path):
    """A PDF of two pages printed as the report is (its write_pdf): page 1 the lab pages' column
    headers in their table and a word drawn twice in one place; page 2 the same headers placed
    at fixed points, running into each other."""
    sys.path.insert(0, os.path.dirname(SCRIPT))
    from progress.layout import write_pdf
    heads = "".join(f"<th>{h}</th>" for h in ("your render", "reference", "difference x16"))
    fixed = "".join(f'<span style="position:absolute; left:{120 + i * 30}pt; top:100pt; font: bold 8pt sans-serif">{h}</span>'
                    for i, h in enumerate(("your render", "reference", "difference x16")))
    write_pdf(f"""<table style="width: 100%; margin-top: 100pt"><tr><th></th>{heads}</tr></table>
      <span style="position:absolute; left:72pt; top:200pt">twice</span><span style="position:absolute; left:72pt; top:200pt">twice</span>
      <div style="break-before: page; position: relative">{fixed}</div>""", path)


def section_pages(path, labs):
    """{lab: the page its section starts on} and the notes' page: a section starts a page
    with its heading (Lab N: name), the notes start the last page."""
    texts = [pdf_text(path, p) for p in range(1, pdf_pages(path) + 1)]
    starts = {}
    for number, text in enumerate(texts, 1):
        first = text.strip().splitlines()[0] if text.strip() else ""
        m = re.match(r"\s*Lab (\d+): (\w+)", first)
        if m and "(continued)" not in first:
            starts[int(m.group(1))] = number
    return starts, texts


def check_sections(path, labs, what):
    """Title page first, each lab's section on pages of its own in order, the notes last."""
    if not os.path.exists(path):
        check(False, f"{what}: no PDF")
        return []
    starts, texts = section_pages(path, labs)
    expected = [n for n, _ in labs]
    check(sorted(starts) == expected and list(starts.values()) == sorted(starts.values()) and
          min(starts.values(), default=0) == 2,
          f"{what}: the title on page 1, then each lab's section from a new page, in order: {starts}")
    check("Progress notes" in texts[-1] or "Week 3 progress" in texts[-1], f"{what}: the notes on the last page")
    return texts


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
        texts = check_sections(out, labs, f"labs {names}")
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
        text = texts[-1]
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
        check_sections(out, labs[:1], "compile error")
        lab_page = pdf_text(out, 2) if os.path.exists(out) else ""
        check("compile error" in lab_page and broken_file in lab_page and "syntax error" in lab_page,
              "compile error: the lab page holds the grader's message")

        for name in ("report.pdf", "broken.pdf"):
            overlaps = word_overlaps(os.path.join(work, name)) if os.path.exists(os.path.join(work, name)) else ["none"]
            check(not overlaps, f"{name}: no words over words: {overlaps[:5]}")

        # 6. Every lab this kit can grade, each with its solution where the kit has it
        # (a student copy has those of the labs before its own), else its starter.
        every = os.path.join(work, "every-lab")
        for n, folder in gradable_labs():
            source = os.path.join(ROOT, "solutions", folder)
            shutil.copytree(source if os.path.isdir(source) else os.path.join(ROOT, "labs", folder),
                            os.path.join(every, folder))
        out = os.path.join(work, "every-lab.pdf")
        run = report(kit_grade, kit_render, "--labs-dir", every, "--notes", notes, "--out", out)
        check(run.returncode == 0, "every lab: exit status 0")
        texts = check_sections(out, gradable_labs(), "every lab")
        # Each lab's score in its section's heading, as the grader gives it (every check passes
        # with a solution; the starter of a lab without one scores less than its weight).
        for n, folder in gradable_labs():
            weight = ("%.3f" % GRADING["labs"][str(n)]["weight"]).rstrip("0").rstrip(".")
            solved = os.path.isdir(os.path.join(ROOT, "solutions", folder))
            heading = next((t for t in texts if re.match(rf"\s*Lab {n}: ", t)), "")
            found = re.search(r"([\d.]+) / ([\d.]+)", heading)
            check(found is not None and found.group(2) == weight and (found.group(1) == weight) == solved,
                  f"every lab: lab {n}'s score in its section, {'full' if solved else 'short of'} {weight}: "
                  f"{found.group(0) if found else 'none'}")
        overlaps = word_overlaps(out) if os.path.exists(out) else ["none"]
        check(not overlaps, f"every lab: no words over words: {overlaps[:5]}")
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
    check_sections(out, labs[:1], "no references")
    text = pdf_text(out) if os.path.exists(out) else ""
    check("Not graded here" in text and "references" in text, "no references: the lab page says why it is not graded")
    check("Progress notes" in text, "no notes: the PDF holds the template")
    overlaps = word_overlaps(out) if os.path.exists(out) else ["none"]
    check(not overlaps, f"no references: no words over words: {overlaps[:5]}")

    # 4. An output that cannot be written.
    blocker = os.path.join(work, "a-file")
    open(blocker, "w").close()
    run = report(kit_grade, kit_render, "--labs", str(first), "--notes", notes, "--out", os.path.join(blocker, "r.pdf"))
    check(run.returncode == 1 and "cannot write" in run.stderr, "unwritable output: exit 1 with 'cannot write'")
    # 5. No kit-grade.
    run = report(os.path.join(work, "no-kit-grade"), kit_render, "--labs", str(first), "--notes", notes,
                 "--out", os.path.join(work, "x.pdf"))
    check(run.returncode == 1 and "kit-grade is not built" in run.stderr, "no kit-grade: exit 1 naming it")

    # The checker sees text over text: headers placed at fixed points that run into each other,
    # and nothing on the page where a table lays them out.
    witness = os.path.join(work, "overlap-witness.pdf")
    overlap_witness(witness)
    overlaps = word_overlaps(witness)
    check(bool(overlaps) and all(page == 2 for page, _, _ in overlaps) and (2, "render", "reference") in overlaps,
          f"witness: the headers placed at fixed points overlap on page 2 ('render' over 'reference'), page 1 has none: {overlaps}")

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
