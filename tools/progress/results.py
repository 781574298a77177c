"""Each lab's results for the progress report: the kit's labs, the grader's verdicts and
scores (kit-grade), the stage's frame time (kit-render --frames), and who and which kit
version made the report."""
import getpass
import json
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LAB_FOLDER = re.compile(r"^(\d\d)-([a-z]+)$")


def kit_stages():
    """{lab number: stage name} from the kit's lab folders (NN-name, the stage table's
    folders): labs/ and solutions/ together, since a student copy for lab N holds the
    starters of labs N and later and the solutions of the others."""
    stages = {}
    for folder in ("labs", "solutions"):
        path = os.path.join(ROOT, folder)
        for m in (LAB_FOLDER.match(n) for n in (os.listdir(path) if os.path.isdir(path) else [])):
            if m:
                stages[int(m.group(1))] = m.group(2)
    return stages


STAGES = kit_stages()

# Frame time: the first frame holds llvmpipe's shader JIT and is dropped; the median of the rest.
TIMING_FRAMES = 6
TIMING_SIZE = "640x480"
TIMING_LIMIT_S = 60  # an endless loop in a shader must not hang the report


class ReportError(Exception):
    pass


def say(message):
    print("progress-report: " + message, file=sys.stderr)


def run_grader(kit_grade, labs_dir, labs, out_dir, references):
    """kit-grade into out_dir. Returns (summary, results) or, when the grader cannot
    grade here because the references are missing, (None, its message)."""
    command = [kit_grade, labs_dir, "--labs", ",".join(map(str, labs)), "--out", out_dir]
    if references:
        command += ["--references", references]
    try:
        run = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=900)
    except subprocess.TimeoutExpired:
        raise ReportError("kit-grade did not finish in 15 minutes")
    message = (run.stderr.strip() or run.stdout.strip()).replace("kit-grade: ", "")
    if run.returncode != 0 or not os.path.exists(os.path.join(out_dir, "summary.json")):
        if "references missing" in message or ("references" in message and "stale" in message):
            return None, message
        raise ReportError("kit-grade could not grade " + labs_dir + ":\n" + message)
    with open(os.path.join(out_dir, "summary.json"), encoding="utf-8") as f:
        summary = json.load(f)
    with open(os.path.join(out_dir, "results.json"), encoding="utf-8") as f:
        results = json.load(f)
    return summary, results


def measure_frame_time(kit_render, labs_dir, lab, image_out):
    """Runs the student's stage on the default scene. Returns a dict with
    median_ms, frames_ms (the ones the median is taken over), renderer and
    command, or error (kit-render's message)."""
    command = [kit_render, "--stage", str(lab), "--shaders", labs_dir, "--scene", "default",
               "--size", TIMING_SIZE, "--frames", str(TIMING_FRAMES), "--timings", "--out", image_out]
    shown = "kit-render --stage {} --shaders {} --scene default --size {} --frames {} --timings".format(
        STAGES[lab], os.path.basename(os.path.normpath(labs_dir)), TIMING_SIZE, TIMING_FRAMES)
    try:
        run = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=TIMING_LIMIT_S)
    except subprocess.TimeoutExpired:
        return {"error": f"kit-render did not finish in {TIMING_LIMIT_S} s (an endless loop?)", "command": shown}
    if run.returncode != 0:
        return {"error": run.stderr.strip().replace("kit-render: ", "") or f"kit-render exited with {run.returncode}",
                "command": shown}
    frames = re.search(r"^frame ms: (.*)$", run.stderr, re.M)
    renderer = re.search(r"^timings: .*?, write [0-9.]+s \((.*)\)$", run.stderr, re.M)
    if not frames:
        return {"error": "kit-render printed no frame times (is it older than --frames?)", "command": shown}
    times = [float(t) for t in frames.group(1).split()][1:]
    return {"median_ms": statistics.median(times), "frames_ms": times, "command": shown,
            "renderer": renderer.group(1) if renderer else "", "image": image_out}


def kit_version():
    try:
        run = subprocess.run(["git", "-C", ROOT, "describe", "--tags", "--always", "--dirty"],
                             capture_output=True, text=True, timeout=20)
        if run.returncode == 0 and run.stdout.strip():
            return run.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    return "unknown (not a git checkout)"


def student_name(given):
    if given:
        return given
    try:
        run = subprocess.run(["git", "-C", ROOT, "config", "user.name"], capture_output=True, text=True, timeout=20)
        if run.returncode == 0 and run.stdout.strip():
            return run.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    try:
        return getpass.getuser()
    except Exception:  # no login name in a container
        return "(unknown: use --student NAME)"
