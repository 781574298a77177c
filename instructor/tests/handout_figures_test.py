#!/usr/bin/env python3
"""The handouts' figures (instructor/handout_figures.py): they match grading's settings now,
and a handout copy with one figure changed is reported, and written back right by --write.
Run: handout_figures_test.py WORK_DIR"""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "instructor" / "handout_figures.py"


def run(*args):
    done = subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def main():
    work = pathlib.Path(sys.argv[1])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    failures = []
    code, out = run()
    if code != 0 or " 0 stale" not in out:
        failures.append(f"the kit's handouts should match, got exit {code}:\n{out}")
    # Witness: lab 2's points per check typed wrong in a copy.
    copy = work / "02-lighting.md"
    text = (ROOT / "handouts" / "02-lighting.md").read_text(encoding="utf-8")
    wrong = text.replace("<!--figure lab2.points_each-->1.25<", "<!--figure lab2.points_each-->1.5<")
    copy.write_text(wrong, encoding="utf-8")
    code, out = run(copy)
    if code != 1 or "lab2.points_each: written '1.5', now '1.25'" not in out:
        failures.append(f"a wrong figure should be reported, got exit {code}:\n{out}")
    code, out = run("--write", copy)
    if code != 0 or copy.read_text(encoding="utf-8") != text:
        failures.append(f"--write should restore the figure, got exit {code}:\n{out}")
    copy.write_text(text.replace("<!--figure lab2.points-->", "<!--figure lab2.pints-->"), encoding="utf-8")
    code, out = run(copy)
    if code != 1 or "lab2.pints: no such figure" not in out:
        failures.append(f"an unknown key should be an error, got exit {code}:\n{out}")
    # Witness: a figure moved to the start of its line, where Markdown would read an HTML block.
    copy.write_text(text.replace("· <!--figure lab2.points-->", "·\n<!--figure lab2.points-->"), encoding="utf-8")
    code, out = run(copy)
    if code != 1 or "lab2.points: a figure starts the line" not in out:
        failures.append(f"a figure at the start of a line should be an error, got exit {code}:\n{out}")
    for f in failures:
        print("FAIL:", f)
    print(f"{5 - len(failures)} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
