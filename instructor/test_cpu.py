#!/usr/bin/env python3
"""Where a test run's CPU goes: runs COMMAND (./kit test, say) and prints the processor time
of each test ctest ran and of each build, as the instructors' figures page lists them.

    test_cpu.py [--build BUILD] [--top N] -- COMMAND [ARG ...]

On a machine whose cores are all busy for the whole run (two cores and ./kit test), the wall
time follows the CPU time, not a test's own wall time: ctest's times (test_times.py) move
with whatever ran beside each test. This reads /proc twice a second while COMMAND runs and
keeps, for each process that ctest started (a test) and each `cmake --build` or ninja (a
build), the largest sum seen of its own and its descendants' user and system time, the
finished descendants included as Linux counts them (those their parents have waited for). A
test's figure can miss the last half second before it ended, so it is a lower bound. Tests
are named by their command in BUILD's ctest list (default build/default, read once COMMAND
has ended). Linux only.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
TICK = os.sysconf("SC_CLK_TCK")
PERIOD = 0.5  # seconds between two readings of /proc


def processes():
    """{pid: (parent pid, (user, system) seconds with waited-for children's, argv)} now."""
    out = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", encoding="ascii", errors="replace") as f:
                stat = f.read()
            with open(f"/proc/{entry}/cmdline", "rb") as f:
                argv = [a.decode(errors="replace") for a in f.read().split(b"\0")[:-1]]
        except OSError:  # it ended meanwhile
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # after the command name, which may hold spaces
        ticks = [int(x) for x in fields[11:15]]  # utime, stime, cutime, cstime
        out[int(entry)] = (int(fields[1]), ((ticks[0] + ticks[2]) / TICK, (ticks[1] + ticks[3]) / TICK), argv)
    return out


def is_build(argv):
    name = os.path.basename(argv[0]) if argv else ""
    return name == "ninja" or (name == "cmake" and "--build" in argv)


def sample(seen, root):
    """Adds this reading to seen: {pid: (largest (user, system) seconds of it and its descendants,
    its argvs)},
    for the processes that descend from root (COMMAND's)."""
    now = processes()
    children = {}
    for pid, (parent, _, _) in now.items():
        children.setdefault(parent, []).append(pid)

    def tree(pid):
        user, system = now[pid][1]
        for child in children.get(pid, []):
            child_user, child_system = tree(child)
            user, system = user + child_user, system + child_system
        return user, system

    def counted(pid):
        """A test (started by ctest, not a ctest itself) or a build."""
        parent, _, argv = now[pid]
        parent_argv = now[parent][2] if parent in now else []
        is_ctest = bool(argv) and os.path.basename(argv[0]) == "ctest"
        return (bool(parent_argv) and os.path.basename(parent_argv[0]) == "ctest" and not is_ctest) or is_build(argv)

    def ours_and_outermost(pid):
        """Descends from root, and no ancestor is counted already (a build a test runs, a test of
        a student copy's own ctest)."""
        parent = now[pid][0]
        while parent in now:
            if parent == root:
                return True
            if counted(parent):
                return False
            parent = now[parent][0]
        return False

    for pid, (_, _, argv) in now.items():
        if counted(pid) and ours_and_outermost(pid):
            # By process: its command line changes where it execs another program (a shim).
            cpu, argvs = seen.get(pid, ((0.0, 0.0), []))
            seen[pid] = (max(cpu, tree(pid), key=sum), argvs if tuple(argv) in argvs else argvs + [tuple(argv)])


def test_names(build):
    """{argv tuple: test name} from ctest's list of BUILD's tests."""
    try:
        listing = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build, capture_output=True, text=True,
                                 check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return {}
    return {tuple(t["command"]): t["name"] for t in json.loads(listing).get("tests", []) if t.get("command")}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build" / "default")
    parser.add_argument("--top", type=int, default=15)
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no COMMAND: test_cpu.py -- ./kit test")
    seen = {}
    start = time.monotonic()
    child = subprocess.Popen(command)
    while child.poll() is None:
        sample(seen, child.pid)
        time.sleep(PERIOD)
    wall = time.monotonic() - start
    usage = os.times()
    names = test_names(args.build)
    rows = []
    for seconds, argvs in seen.values():
        named = [names[a] for a in argvs if a in names]
        key = argvs[0]
        if named:
            what = f"`{named[0]}`"
        elif is_build(list(key)):
            what = "build: `" + " ".join(os.path.basename(a) if i == 0 else a for i, a in enumerate(key)) + "`"
        else:
            what = "`" + " ".join(key)[:100] + "`"
        rows.append((sum(seconds), seconds[1], what))
    rows.sort(reverse=True)
    print("| CPU seconds | of them system | test or build |\n|---:|---:|---|")
    for seconds, system, what in rows[: args.top]:
        print(f"| {seconds:.0f} | {system:.0f} | {what} |")
    cpu = usage.children_user + usage.children_system
    print(f"\n{' '.join(command)}: exit {child.returncode}, {wall:.0f} s wall, {cpu:.0f} s of CPU in all "
          f"({usage.children_system:.0f} of them system), on {os.cpu_count()} cores")
    return child.returncode


if __name__ == "__main__":
    sys.exit(main())
