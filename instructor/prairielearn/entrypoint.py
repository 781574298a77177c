#!/usr/bin/env python3
"""PrairieLearn's external grader runs this for every submission of a kit question.

It grades GRADE_ROOT/student (pl-file-upload puts the lab's files there, loose) with
kit-grade and writes GRADE_ROOT/results/results.json from kit-grade's summary.json
(platform_results.py, beside this file). Whatever goes wrong, a valid results.json is
written: a submission without one of the lab's files, or a broken autograder, is
"gradable": false (no points and no attempt lost), with a message saying which.

Where things are (instructor/prairielearn/README.md):
  GRADE_ROOT/tests/lab.json          the question's lab: number, folder, files, limits
  <this folder>/kit/                 the kit's grading data (solutions, shaders, references,
                                     grading.json): serverFilesCourse, never shown to students
  KIT_GRADE_BIN                      kit-grade, built into the grading image

Environment (for testing it without Docker; instructor/tests/prairielearn_test.sh):
  GRADE_ROOT      the /grade folder (default /grade)
  KIT_GRADE_BIN   a kit-grade already built (default /opt/kit/build/default/tools/kit-grade)
  KIT_CPU_LIMIT, KIT_TIMEOUT   kit-grade's --cpu-limit / --timeout instead of lab.json's
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import platform_results  # noqa: E402  (beside this file: serverFilesCourse)

GRADE_ROOT = Path(os.environ.get("GRADE_ROOT") or "/grade")
RESULTS = GRADE_ROOT / "results" / "results.json"
KIT = HERE / "kit"
GRADER = os.environ.get("KIT_GRADE_BIN") or "/opt/kit/build/default/tools/kit-grade"


def say(text):
    print(f"entrypoint: {text}", file=sys.stderr, flush=True)


def write(result):
    # PrairieLearn does not create results/ (docs/externalGrading.md).
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(result, ensure_ascii=False)
    if len(text.encode("utf-8")) > platform_results.PRAIRIELEARN_LIMIT:  # never expected: drop every image
        for test in result.get("tests", []):
            test.pop("images", None)
        result["output"] = result.get("output", "") + "\nImages left out: the results were over 1 MB."
        text = json.dumps(result, ensure_ascii=False)
    RESULTS.write_text(text, encoding="utf-8")
    say(f"wrote {RESULTS} ({len(text)} bytes): {result.get('message', '')}")


def autograder_problem(text):
    write(platform_results.prairielearn_error(
        f"{text} This is a problem with the autograder, not with your files: no attempt was counted; "
        "please tell your instructor."))
    return 0


def main():
    start = time.monotonic()
    try:
        lab = json.loads((GRADE_ROOT / "tests" / "lab.json").read_text(encoding="utf-8"))
        n, folder, files = int(lab["lab"]), lab["folder"], list(lab["files"])
    except (OSError, ValueError, KeyError) as e:
        return autograder_problem(f"The question has no valid tests/lab.json ({e}).")
    if not Path(GRADER).is_file() or not os.access(GRADER, os.X_OK):
        return autograder_problem(f"kit-grade is not in the grading image ({GRADER}).")

    work = Path(tempfile.mkdtemp(prefix="kit-pl-"))
    try:
        return grade(lab, n, folder, files, work, start)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def grade(lab, n, folder, files, work, start):
    student = GRADE_ROOT / "student"
    staged, found, missing = platform_results.stage_loose(student, folder, files, work / "submission")
    if staged is None and student.is_dir() and not found and platform_results._lab_dirs_inside(student):
        staged = student  # an NN-name/ folder (a zip-like layout): kit-grade reads it and names what is missing
    elif missing:
        write({"gradable": False,
               "format_errors": [f"Missing file: {name} (lab {n} needs {', '.join(files)})" for name in missing],
               "message": f"Not graded: {', '.join(missing)} missing. No attempt was counted."})
        return 0

    cpu = os.environ.get("KIT_CPU_LIMIT") or str(lab.get("cpu_limit", 20))
    wall = os.environ.get("KIT_TIMEOUT") or str(lab.get("wall_limit", 40))
    out = work / "out"
    say(f"grading lab {n} of {staged}")
    try:
        run = platform_results.run_kit_grade(GRADER, staged, n, KIT, out, ["--cpu-limit", cpu, "--timeout", wall],
                                             timeout=float(wall) + 30)  # kit-grade stops the renderer at `wall`
    except (OSError, subprocess.TimeoutExpired) as e:
        return autograder_problem(f"kit-grade did not run to the end ({e}).")
    if not (out / "summary.json").is_file():
        return autograder_problem(f"kit-grade stopped with exit status {run.returncode} and wrote no summary.")
    try:
        result = platform_results.prairielearn(out, n, KIT / "tools" / "grade" / "grading.json")
    except (OSError, ValueError, KeyError) as e:
        return autograder_problem(f"kit-grade's summary could not be read ({e}).")
    write(result)
    say(f"graded lab {n} in {time.monotonic() - start:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Exception as e:  # a valid results.json whatever happens
        autograder_problem(f"The autograder failed: {type(e).__name__}: {e}.")
        sys.exit(0)
