#!/usr/bin/python3
"""The PDF progress report a student hands in: ./kit progress-report.

For each lab: the grader's checks (kit-grade on the student's labs/ folder),
each with the student's render, the reference and their difference, the
verdicts and scores, and the stage's frame time (kit-render --frames). Then
the student's notes (a Markdown file) and, first, a title page.

The layout is HTML (progress/report.mustache, the one the page's "Progress
report" fills too), printed to PDF by WeasyPrint; the notes' Markdown is rendered
by markdown-it-py (Debian's weasyprint, python3-markdown-it and python3-pystache,
for /usr/bin/python3). This file reads the command line; the modules of
progress/ beside it collect the results and fill the layout (progress/__init__.py).
"""
import argparse
import datetime
import os
import re
import sys
import tempfile

# The progress/ package beside this file, also when the file is loaded by its path
# (tests/progress_report_test.py).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from progress.layout import check_modules, format_score, render_html, report_fields, write_pdf  # noqa: E402
from progress.results import (ROOT, LAB_FOLDER, STAGES, TIMING_FRAMES, TIMING_SIZE, ReportError,  # noqa: E402
                              kit_version, measure_frame_time, run_grader, say, student_name)

NOTES_TEMPLATE = """\
# Progress notes

Write here what you did in each lab, what went wrong and how you fixed it.
`./kit progress-report` puts this file at the end of the PDF, as Markdown: headings,
paragraphs, lists, `inline code`, **bold**, *italic*, code blocks and tables.

## What I did

- Lab 1: ...

## Problems and how I solved them

- ...

## Open questions

- ...
"""


# ---------------------------------------------------------------- arguments

def parse_lab_list(text):
    labs = set()
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
        name = [n for n, s in STAGES.items() if s == part]
        if name:
            labs.add(name[0])
        elif m:
            a, b = int(m.group(1)), int(m.group(2) or m.group(1))
            if a > b or a not in STAGES or b not in STAGES:
                raise ReportError(f"--labs: '{part}' is not a lab ({min(STAGES)} to {max(STAGES)})")
            labs.update(range(a, b + 1))
        else:
            raise ReportError(f"--labs: '{part}' is not a lab number, range (1-3) or stage name")
    if not labs:
        raise ReportError("--labs: no lab given")
    return sorted(labs)


def labs_present(labs_dir):
    if not os.path.isdir(labs_dir):
        raise ReportError(f"no labs folder at {labs_dir}")
    found = sorted(int(m.group(1)) for m in (LAB_FOLDER.match(n) for n in os.listdir(labs_dir))
                   if m and os.path.isdir(os.path.join(labs_dir, m.group(0))))
    if not found:
        raise ReportError(f"no lab folders (01-gbuffer, ...) in {labs_dir}")
    # Only the labs this kit can assemble: a stage is built on the solutions of the
    # labs before it, and a student copy for lab N has those of labs 1..N-1 alone.
    solutions = os.path.join(ROOT, "solutions")
    released = {int(m.group(1)) for m in (LAB_FOLDER.match(n) for n in os.listdir(solutions)) if m} \
        if os.path.isdir(solutions) else set()
    usable = [n for n in found if all(k in released for k in range(1, n))]
    if len(usable) < len(found):
        print(f"progress-report: labs {', '.join(str(n) for n in found if n not in usable)} left out: "
              "they are built on solutions this kit does not have yet", file=sys.stderr)
    if not usable:
        raise ReportError(f"no lab in {labs_dir} can be rendered here: the solutions they build on are missing")
    return usable


def check_output_path(out):
    if os.path.isdir(out):
        raise ReportError(f"cannot write {out}: it is a folder (give a file name, e.g. {os.path.join(out, 'report.pdf')})")
    folder = os.path.dirname(out) or "."
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise ReportError(f"cannot write {out}: cannot create {folder} ({e.strerror})")
    if not os.access(folder, os.W_OK | os.X_OK) or (os.path.exists(out) and not os.access(out, os.W_OK)):
        raise ReportError(f"cannot write {out}: permission denied")


# ---------------------------------------------------------------- main

def main(argv):
    parser = argparse.ArgumentParser(
        prog="./kit progress-report",
        description="Writes a PDF progress report: your labs' grades, renders and frame times, and your notes.")
    parser.add_argument("--labs", help="labs to include, e.g. 1,2 or 1-3 (default: every lab folder in labs/)")
    parser.add_argument("--notes", help="your notes in Markdown (default: progress-notes.md at the kit root; "
                                        "created from a template when missing)")
    parser.add_argument("--out", help="the PDF to write (default: out/progress-report.pdf)")
    parser.add_argument("--student", help="the name on the title page (default: git config user.name, else the login)")
    parser.add_argument("--labs-dir", help="the folder holding your NN-name lab folders (default: labs/)")
    parser.add_argument("--kit-grade", help=argparse.SUPPRESS)
    parser.add_argument("--kit-render", help=argparse.SUPPRESS)
    parser.add_argument("--references", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    check_modules()
    build_tools = os.path.join(ROOT, "build", "default", "tools")
    kit_grade = args.kit_grade or os.path.join(build_tools, "kit-grade")
    kit_render = args.kit_render or os.path.join(build_tools, "kit-render")
    for name, path in (("kit-grade", kit_grade), ("kit-render", kit_render)):
        if not (os.path.isfile(path) and os.access(path, os.X_OK)):
            raise ReportError(f"{name} is not built ({path} is missing): run ./kit setup first")
    labs_dir = os.path.abspath(args.labs_dir or os.path.join(ROOT, "labs"))
    out = os.path.abspath(args.out or os.path.join(ROOT, "out", "progress-report.pdf"))
    notes_path = os.path.abspath(args.notes or os.path.join(ROOT, "progress-notes.md"))
    labs = parse_lab_list(args.labs) if args.labs else labs_present(labs_dir)
    if not os.path.isdir(labs_dir):
        raise ReportError(f"no labs folder at {labs_dir}")
    check_output_path(out)

    if os.path.exists(notes_path):
        try:
            with open(notes_path, encoding="utf-8", errors="replace") as f:
                notes_text = f.read()
        except OSError as e:
            raise ReportError(f"cannot read the notes {notes_path}: {e.strerror}")
    else:
        notes_text = NOTES_TEMPLATE
        try:
            os.makedirs(os.path.dirname(notes_path), exist_ok=True)
            with open(notes_path, "x", encoding="utf-8") as f:
                f.write(NOTES_TEMPLATE)
            say(f"no notes file: wrote a template to {notes_path}; edit it and run this again "
                "(the PDF below holds the template)")
        except OSError as e:
            say(f"no notes file at {notes_path}, and a template could not be written there ({e.strerror}); "
                "the PDF holds the template")

    with tempfile.TemporaryDirectory(prefix="kit-progress-") as temp:
        grade_dir = os.path.join(temp, "grade")
        say(f"grading labs {', '.join(map(str, labs))} of {labs_dir} with kit-grade")
        summary, results = run_grader(kit_grade, labs_dir, labs, grade_dir, args.references)
        problem = ""
        if summary is None:
            problem = ("the grader's references are missing (a student copy of the kit does not hold "
                       "tools/grade/references/). kit-grade said: " + results)
            say("not graded: " + problem)
        timings = {}
        for lab in labs:
            entry = summary["labs"].get(str(lab)) if summary else None
            if entry and entry["status"] != "graded":
                timings[lab] = {"error": f"the lab did not render in the grader ({entry['status'].replace('_', ' ')})"}
                continue
            say(f"timing lab {lab} ({STAGES[lab]}): {TIMING_FRAMES} frames at {TIMING_SIZE}")
            timings[lab] = measure_frame_time(kit_render, labs_dir, lab, os.path.join(temp, f"lab{lab}-render.png"))

        info = {"student": student_name(args.student), "version": kit_version(), "labs_dir": os.path.relpath(labs_dir, ROOT)
                if labs_dir.startswith(ROOT + os.sep) else labs_dir,
                "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M")}
        partial = os.path.join(os.path.dirname(out), "." + os.path.basename(out) + f".{os.getpid()}.tmp")
        fields = report_fields(info, labs, summary, results, grade_dir, timings, problem, notes_text,
                               os.path.relpath(notes_path, ROOT) if notes_path.startswith(ROOT + os.sep) else notes_path)
        try:
            pages = write_pdf(render_html(fields), partial)
            os.replace(partial, out)
        except OSError as e:
            raise ReportError(f"cannot write {out}: {e.strerror or e}")
        finally:
            if os.path.exists(partial):
                os.unlink(partial)
    total = sum(summary["labs"][str(l)]["score"] for l in labs if summary and str(l) in summary["labs"])
    max_total = sum(summary["labs"][str(l)]["max_score"] for l in labs if summary and str(l) in summary["labs"])
    say(f"{pages} pages; " + (f"total {format_score(total)}/{format_score(max_total)}" if summary else "not graded"))
    print(out)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except ReportError as e:
        say(str(e))
        sys.exit(1)
    except KeyboardInterrupt:
        sys.exit(130)
