#!/usr/bin/env python3
"""The slowest tests of the last ctest run in a build, as the instructors' figures page lists them.

    test_times.py [BUILD] [--top N]

BUILD (default build/default) is read for Testing/Temporary/LastTest.log, which ctest writes
on every run: each test's wall time, in seconds, as ctest measured it (two at a time on two
cores, as ./kit test runs them). Prints a Markdown table of the N (default 10) slowest, then
the run's total of test time.
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def times(log):
    """[(test, seconds, passed)] in the log's order."""
    out, name = [], None
    for line in log.read_text(encoding="utf-8", errors="replace").splitlines():
        m = re.match(r"\d+/\d+ Testing: (\S+)", line)
        if m:
            name = m.group(1)
            continue
        m = re.match(r"Test time =\s+([0-9.]+) sec", line)
        if m and name:
            out.append([name, float(m.group(1)), None])
        if line.startswith("Test Passed") and out:
            out[-1][2] = True
        elif line.startswith("Test Failed") and out:
            out[-1][2] = False
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("build", nargs="?", type=pathlib.Path, default=ROOT / "build" / "default")
    parser.add_argument("--top", type=int, default=10)
    args = parser.parse_args(argv)
    log = args.build / "Testing" / "Temporary" / "LastTest.log"
    if not log.is_file():
        print(f"test_times: no {log}: run ./kit test first", file=sys.stderr)
        return 1
    rows = times(log)
    print("| test | seconds | result |\n|---|---:|---|")
    for name, seconds, passed in sorted(rows, key=lambda r: -r[1])[: args.top]:
        print(f"| `{name}` | {seconds:.0f} | {'passed' if passed else 'FAILED'} |")
    print(f"\n{len(rows)} tests, {sum(r[1] for r in rows):.0f} s of test time in all")
    return 0


if __name__ == "__main__":
    sys.exit(main())
