#!/usr/bin/env python3
"""Classroom 50 runs this once per submission (CLASSROOM/autograders/ASSIGNMENT/autograder.py),
in the student's repository's GitHub Actions job, with the student's checkout as the working
directory.

It grades ./labs/ (the student's lab files, nothing else of the checkout) with kit-grade and
writes ./result.json (classroom50/result/v1: one test per check, integer scores) from
kit-grade's summary.json through platform_results.py, and ./kit-grade-report.html (the
report, images inlined) for the assignment's release_assets.

What grades comes from this bundle, never from the checkout (the student owns it and may
edit anything in it): bundle.json (the lab), kit/ beside this file (the student copy for the
lab less labs/: the grader's sources, the earlier labs' solutions, shaders, references and
grading.json), built here with kit/kit setup --grading. kit-grade is pointed at kit/ with
KIT_ROOT, --config and --references. Nothing in the bundle is secret: students already have
all of it.

Exit status: 0 whenever grading ran end to end, whatever the score; non-zero when the set-up
is broken (the build failed, kit-grade wrote no summary): Classroom 50 then reports an error
instead of a grade.

Environment: the runner's CLASSROOM, ASSIGNMENT, SUBMISSION_TAG, COMMIT_URL, RELEASE_URL,
REVIEW_URL; for testing, KIT_GRADE_BIN (a kit-grade already built: no build here; set
KIT_SCENE_DIR beside it).
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
import platform_results  # noqa: E402  (beside this file, in the bundle)

KIT = HERE / "kit"
REPORT = "kit-grade-report.html"  # the name release_assets lists


def say(text):
    print(f"autograder: {text}", file=sys.stderr, flush=True)


def broken(text):
    print(f"::error::{text}", file=sys.stderr, flush=True)
    return 1


def build():
    """kit-grade from the bundle's sources (the runtime's apt list installed the packages)."""
    grader = KIT / "build" / "default" / "tools" / "kit-grade"
    if grader.is_file():
        return grader
    start = time.monotonic()
    # Debian's python3 first: the build runs glad, a python3-glad script, and the runner's
    # PATH leads to the runtime's own Python.
    env = dict(os.environ, PATH="/usr/bin:/bin:" + os.environ.get("PATH", ""))
    say("building kit-grade from the bundle (kit/kit setup --grading)")
    subprocess.run([str(KIT / "kit"), "setup", "--grading"], cwd=KIT, env=env, check=True)
    say(f"built in {time.monotonic() - start:.0f} s")
    return grader


def main():
    try:
        bundle = json.loads((HERE / "bundle.json").read_text(encoding="utf-8"))
        lab = int(bundle["lab"])
    except (OSError, ValueError, KeyError) as e:
        return broken(f"the bundle has no valid bundle.json ({e})")
    try:
        grader = Path(os.environ["KIT_GRADE_BIN"]) if os.environ.get("KIT_GRADE_BIN") else build()
    except (OSError, subprocess.CalledProcessError) as e:
        return broken(f"kit-grade could not be built: {e}")
    if not grader.is_file():
        return broken(f"no kit-grade at {grader}")

    config = KIT / "tools" / "grade" / "grading.json"
    work = Path(tempfile.mkdtemp(prefix="kit-c50-"))
    try:
        out = work / "out"
        start = time.monotonic()
        # labs/ of the checkout only: its solutions/ or tools/ never reach the grader. No labs/
        # at all is the student's doing: graded as an empty folder (files missing, 0 points).
        labs = Path.cwd() / "labs"
        if not labs.is_dir():
            labs = work / "labs"
            labs.mkdir()
        run = platform_results.run_kit_grade(grader, labs, lab, KIT, out)
        if not (out / "summary.json").is_file():
            return broken(f"kit-grade stopped with exit status {run.returncode} and wrote no summary")
        result = platform_results.classroom50(out, [lab], config, os.environ, cwd=Path.cwd())
        Path("result.json").write_text(json.dumps(result, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        try:
            platform_results.self_contained_report(out, REPORT)
        except OSError as e:  # the report is an extra: the grade stands without it
            say(f"no {REPORT}: {e}")
        say(f"lab {lab}: {result['score']}/{result['max-score']} in {time.monotonic() - start:.1f} s "
            f"(result.json, {REPORT})")
        return 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
