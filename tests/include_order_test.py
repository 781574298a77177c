#!/usr/bin/env python3
"""The include order of common/ and tools/grade/ (common/include_order.py, tests/include_order.cmake).

  1. the kit's common/ and tools/grade/ pass: every include runs from a group to itself or
     an earlier one;
  2. witness: a copy of common/'s CMakeLists.txt over a planted tree in which base/
     includes render/ and a file includes a group's header without its group is
     refused, naming both lines;
  3. witness: a copy of tools/grade.cmake over a planted tools/grade/ in which verdict/
     includes run/grader.h (the outcome types' old home) and intake/sandbox.h is refused,
     naming both lines, while run/ including verdict/ and main.cpp including batch/ pass.
Run: include_order_test.py WORK_DIR
"""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "common" / "include_order.py"


def run(*folders):
    done = subprocess.run([sys.executable, str(SCRIPT), *map(str, folders)], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def main():
    work = pathlib.Path(sys.argv[1])
    failures = []
    checks = 0

    for folder in (ROOT / "common", ROOT / "tools" / "grade"):
        checks += 1
        code, out = run(folder)
        if code != 0 or "every include runs downwards" not in out:
            failures.append(f"the kit's {folder.relative_to(ROOT)}/ should pass, got exit {code}:\n{out}")

    shutil.rmtree(work, ignore_errors=True)
    checks += 1
    planted = work / "common"
    (planted / "base").mkdir(parents=True)
    (planted / "render").mkdir()
    shutil.copy(ROOT / "common" / "CMakeLists.txt", planted / "CMakeLists.txt")
    (planted / "render" / "renderer.h").write_text('#pragma once\n#include "base/error.h"\n')
    (planted / "base" / "error.h").write_text('#pragma once\n#include <string>\n#include "render/renderer.h"\n')
    (planted / "base" / "text.cpp").write_text('#include "error.h"\n')
    code, out = run(planted)
    expected = ["base/error.h:3: base/ includes render/renderer.h, of the later group render/",
                'base/text.cpp:1: includes "error.h": write it as "group/error.h"']
    if code != 1 or any(line not in out for line in expected):
        failures.append(f"the planted common/ should fail naming {expected}, got exit {code}:\n{out}")
    if "renderer.h:2" in out:
        failures.append(f"render/ including base/ runs downwards and must pass:\n{out}")

    checks += 1
    grade = work / "tools" / "grade"
    for group in ("verdict", "intake", "run", "batch"):
        (grade / group).mkdir(parents=True)
    shutil.copy(ROOT / "tools" / "grade.cmake", work / "tools" / "grade.cmake")
    (grade / "intake" / "sandbox.h").write_text('#pragma once\n')
    (grade / "verdict" / "outcome.h").write_text('#pragma once\n')
    (grade / "verdict" / "lab_verdict.h").write_text(
        '#pragma once\n#include "intake/sandbox.h"\n#include "run/grader.h"\n#include "verdict/outcome.h"\n')
    (grade / "run" / "grader.h").write_text('#pragma once\n#include "verdict/outcome.h"\n')
    (grade / "batch" / "batch.h").write_text('#pragma once\n#include "run/grader.h"\n')
    (grade / "main.cpp").write_text('#include "batch/batch.h"\n#include "run/grader.h"\n')
    code, out = run(grade)
    expected = ["verdict/lab_verdict.h:2: verdict/ includes intake/sandbox.h, of the later group intake/",
                "verdict/lab_verdict.h:3: verdict/ includes run/grader.h, of the later group run/"]
    if code != 1 or any(line not in out for line in expected):
        failures.append(f"the planted tools/grade/ should fail naming {expected}, got exit {code}:\n{out}")
    if any(passing in out for passing in ("lab_verdict.h:4", "grader.h:2", "batch.h:2", "main.cpp")):
        failures.append(f"includes of the same or an earlier group, and main.cpp's, run downwards and must pass:\n{out}")

    for failure in failures:
        print("FAIL:", failure)
    print(f"{checks - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
