#!/usr/bin/env python3
"""common/'s include order (common/include_order.py, tests/include_order.cmake).

  1. the kit's common/ passes: every include runs from a group to itself or an earlier one;
  2. witness: a copy of common/'s CMakeLists.txt over a planted tree in which base/
     includes render/ and a file includes a group's header without its group is
     refused, naming both lines.
Run: include_order_test.py WORK_DIR
"""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "common" / "include_order.py"


def run(common):
    done = subprocess.run([sys.executable, str(SCRIPT), str(common)], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def main():
    work = pathlib.Path(sys.argv[1])
    failures = []

    code, out = run(ROOT / "common")
    if code != 0 or "every include runs downwards" not in out:
        failures.append(f"the kit's common/ should pass, got exit {code}:\n{out}")

    planted = work / "common"
    shutil.rmtree(work, ignore_errors=True)
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
        failures.append(f"the planted tree should fail naming {expected}, got exit {code}:\n{out}")
    if "renderer.h:2" in out:
        failures.append(f"render/ including base/ runs downwards and must pass:\n{out}")

    for failure in failures:
        print("FAIL:", failure)
    print(f"{2 - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
