#!/usr/bin/env python3
"""One grading run, every platform: turns kit-grade's OUT folder into each platform's result.

kit-grade grades once and writes OUT/summary.json (per lab and per check: score,
max_score, passed, summary, image/reference/diff under OUT/img/). The platforms'
files are written from that summary, never by grading again, so Gradescope
(kit-grade's own OUT/results.json), PrairieLearn and Classroom 50 give the same
verdict for the same submission:

  prairielearn(out, lab)     PrairieLearn's results.json (score in [0, 1], tests,
                             data: URL images kept under 1 MB, gradable: false
                             for a submission that is not one)
  classroom50(out, ...)      Classroom 50's result.json (classroom50/result/v1,
                             integer scores, one test per check)
  stage_loose(...)           lab files uploaded on their own, put into NN-name/
                             (Gradescope's run_autograder and the PrairieLearn
                             entrypoint both use it)
  self_contained_report(out) report.html with its images inlined (one file, for a
                             Classroom 50 release asset)
  run_kit_grade(...)         kit-grade on one lab, with the kit's references and
                             grading.json (the PrairieLearn entrypoint, autograder.py)

Python 3.11 standard library only: it runs in Gradescope's and PrairieLearn's
images and on Classroom 50's runner. It is copied beside the PrairieLearn
entrypoint and the Classroom 50 autograder.py by their package scripts; this
file is the one source.

Command line (for the shell scripts):
  platform_results.py folders --kit KIT [--labs 1,2]
      prints the NN-name folders of the labs (every lab of KIT, or those --labs names),
      one a line; exit 1 naming a lab KIT does not have
  platform_results.py stage --kit KIT --lab N --submission DIR --dest DIR
      prints the staged folder when the lab's files lay loose in DIR (and at least one
      was found), nothing otherwise; missing files are named on stderr
"""
import argparse
import base64
import datetime
import html
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

# PrairieLearn's limit on results.json is 1 MB; a margin for what PrairieLearn adds.
PRAIRIELEARN_LIMIT = 1_000_000
PRAIRIELEARN_MARGIN = 20_000
# Statuses (tools/grade/verdict/outcome.h) that say the submission is not one PrairieLearn can grade:
# no attempt is counted against the student.
NOT_A_SUBMISSION = {"missing_files", "invalid_files"}
STATUS_TEXT = {
    "compile_error": "compile error",
    "timeout": "timed out",
    "crash": "the renderer crashed",
    "non_finite_map": "NaN or Inf in a map",
    "missing_files": "files missing",
    "invalid_files": "files refused",
    "error": "the grader could not grade",
}


# --- the lab table ---------------------------------------------------------------------

def lab_folder(kit, lab):
    """(folder name, [file names]) of lab `lab` from the kit's solutions/ (else labs/)."""
    prefix = f"{int(lab):02d}-"
    for parent in ("solutions", "labs"):
        root = Path(kit) / parent
        if not root.is_dir():
            continue
        for d in sorted(root.iterdir()):
            if d.is_dir() and d.name.startswith(prefix):
                return d.name, sorted(p.name for p in d.iterdir() if p.is_file())
    raise LookupError(f"the kit at {kit} has no lab {lab} (solutions/ or labs/)")


def lab_folders(kit, spec=""):
    """The NN-name folders of the kit's labs (solutions/ and labs/ together) in order, or
    those `spec` ("1,2") names. LookupError for a malformed spec or a lab the kit has not."""
    if not spec:
        return sorted({d.name for parent in ("solutions", "labs") if (Path(kit) / parent).is_dir()
                       for d in (Path(kit) / parent).iterdir() if d.is_dir() and re.match(r"^\d\d-", d.name)})
    if not re.fullmatch(r"\d+(,\d+)*", spec):
        raise LookupError(f"expects lab numbers separated by commas (got '{spec}')")
    return [lab_folder(kit, n)[0] for n in spec.split(",")]


def run_kit_grade(grader, submission, lab, kit, out, extra=(), timeout=None):
    """kit-grade on lab `lab` of `submission` into `out`, against `kit`: its earlier labs'
    solutions and shaders (KIT_ROOT), references and grading.json, never those of the
    machine's kit or the student's checkout. Returns the finished process (what it printed
    is passed on to stderr); raises subprocess.TimeoutExpired past `timeout` seconds."""
    grade = Path(kit) / "tools" / "grade"
    command = [str(grader), str(submission), "--labs", str(lab), "--out", str(out),
               "--config", str(grade / "grading.json"), "--references", str(grade / "references"), *extra]
    run = subprocess.run(command, env=dict(os.environ, KIT_ROOT=str(kit)), capture_output=True, text=True,
                         timeout=timeout)
    sys.stderr.write(run.stdout + run.stderr)
    return run


def check_order(config, lab):
    """Check ids of lab `lab` in grading.json's order (the order Gradescope's tests have)."""
    if not config:
        return []
    try:
        labs = json.loads(Path(config).read_text(encoding="utf-8"))["labs"]
        return list(labs[str(lab)]["checks"])
    except (OSError, ValueError, KeyError):
        return []


def check_points(config, lab):
    """{check id: integer points} of lab `lab` from grading.json."""
    labs = json.loads(Path(config).read_text(encoding="utf-8"))["labs"]
    return {k: int(v) for k, v in labs[str(lab)]["checks"].items()}


def load_summary(out):
    return json.loads((Path(out) / "summary.json").read_text(encoding="utf-8"))


def ordered_checks(lab_entry, order):
    checks = lab_entry.get("checks") or {}
    ids = [c for c in order if c in checks] + sorted(c for c in checks if c not in order)
    return [(c, checks[c]) for c in ids]


def lab_label(n, lab_entry):
    return f"lab {n} {lab_entry.get('name', '')}".strip()


# --- staging loose uploads --------------------------------------------------------------

def _lab_dirs_inside(submission):
    """NN-name folders at most two levels down (the layouts kit-grade reads itself)."""
    out = []
    for depth1 in submission.iterdir():
        if depth1.is_dir() and not depth1.is_symlink():
            if re.match(r"^\d\d-", depth1.name):
                out.append(depth1)
            for depth2 in depth1.iterdir():
                if depth2.is_dir() and re.match(r"^\d\d-", depth2.name):
                    out.append(depth2)
    return out


def stage_loose(submission, folder, files, dest):
    """The lab's files uploaded on their own (Gradescope's drag and drop, PrairieLearn's
    pl-file-upload): copied into dest/folder/. Returns (dest or None, found, missing):
    None when the submission already has lab folders (kit-grade reads those itself) or
    none of the files lies at its top. Links are never followed."""
    submission, dest = Path(submission), Path(dest)
    if not submission.is_dir() or _lab_dirs_inside(submission):
        return None, [], list(files)
    found, missing = [], []
    for name in files:
        src = submission / name
        if src.is_file() and not src.is_symlink():
            found.append(name)
        else:
            missing.append(name)
    if not found:
        return None, found, missing
    (dest / folder).mkdir(parents=True, exist_ok=True)
    for name in found:
        shutil.copyfile(submission / name, dest / folder / name)
    return dest, found, missing


# --- PrairieLearn -----------------------------------------------------------------------

def _data_url(path):
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def _size(obj):
    return len(json.dumps(obj, ensure_ascii=False).encode("utf-8"))


def prairielearn(out, lab, config=None, limit=PRAIRIELEARN_LIMIT):
    """PrairieLearn's results.json for lab `lab` of kit-grade's OUT folder, under `limit` bytes."""
    out = Path(out)
    summary = load_summary(out)
    entry = summary["labs"][str(lab)]
    label = lab_label(lab, entry)
    status = entry.get("status", "")
    message = entry.get("message", "")
    if status in NOT_A_SUBMISSION or status == "error":
        why = (message if status != "error" else
               f"The grader could not grade this submission ({message}). This is a problem with the "
               "autograder, not with your files: please tell your instructor.")
        return {"gradable": False, "format_errors": [f"{label}: {why}"],
                "message": f"{label}: not graded: {STATUS_TEXT.get(status, status)}. No attempt was counted."}

    max_score = float(entry.get("max_score") or 0)
    score = float(entry.get("score") or 0)
    checks = ordered_checks(entry, check_order(config, lab))
    tests, failed = [], []
    for i, (cid, c) in enumerate(checks):
        test = {"name": f"{label}: {c.get('title', cid)}", "points": c.get("score", 0.0),
                "max_points": c.get("max_score", 0.0)}
        if status != "graded":
            test["message"] = f"Not graded: {STATUS_TEXT.get(status, status)}."
            test["output"] = message if i == 0 else f"See the first test of {label} for the message."
        else:
            test["message"] = "Passed." if c.get("passed") else "Failed."
            test["output"] = (c.get("summary", "") + (f"\n{c['note']}" if c.get("note") else "") +
                              (f"\nAt {c['worst_pixel']}." if c.get("worst_pixel") else ""))
            if not c.get("passed"):
                failed.append((test, c))
                if entry.get("likely_text"):  # kit-grade's guess at the mistake (tools/grade/verdict/diagnosis.h)
                    test["output"] = entry["likely_text"] + "\n" + test["output"]
                # The probed functions that differ, with their inputs (tools/grade/frames/function_probes.h),
                # under the lab's first failed check.
                if len(failed) == 1:
                    for line in entry.get("functions_text", []):
                        test["output"] += f"\n{line}"
        tests.append(test)
    if not tests:  # a lab with no check listed: one test carries the verdict
        tests.append({"name": label, "points": score, "max_points": max_score,
                      "message": STATUS_TEXT.get(status, status), "output": message})

    passed = entry.get("checks_passed", 0)
    headline = (f"{label}: {score:g}/{max_score:g} ({passed} of {len(checks)} checks passed)" if status == "graded"
                else f"{label}: 0/{max_score:g}, not graded: {STATUS_TEXT.get(status, status)}")
    output = [headline]
    if message:
        output.append(message)
    output += summary.get("notes", [])
    output.append(f"Rendered with {summary.get('renderer', '?')}.")
    result = {"gradable": True, "score": round(score / max_score, 6) if max_score > 0 else 0.0,
              "message": headline, "output": "\n".join(output), "tests": tests}

    # Images for the failed checks, most useful first across all of them (every student
    # render, then every difference, then every reference), while the file stays under
    # the limit; what does not fit is named.
    budget = limit - PRAIRIELEARN_MARGIN - _size(result)
    left_out = []
    for key, caption in (("image", "your render"), ("diff", "difference"), ("reference", "reference")):
        for test, c in failed:
            rel = c.get(key)
            path = out / rel if rel else None
            if not path or not path.is_file():
                continue
            image = {"label": f"{c.get('title', '')}: {caption}", "url": _data_url(path)}
            cost = _size(image) + 16
            if cost <= budget:
                test.setdefault("images", []).append(image)
                budget -= cost
            else:
                left_out.append(f"{test['name']} ({caption})")
                test["output"] += f"\n[{caption} image left out: results are limited to 1 MB]"
    if left_out:
        note = (f"{len(left_out)} image(s) left out to keep the results under PrairieLearn's 1 MB: "
                + "; ".join(left_out))
        result["output"] += "\n" + note
        while _size(result) > limit - PRAIRIELEARN_MARGIN // 2 and "; " in result["output"]:
            result["output"] = result["output"].rsplit("; ", 1)[0] + " ..."  # never over for the list
    return result


def prairielearn_error(text):
    """A results.json for a grading run that went wrong before there was a summary."""
    return {"gradable": False, "format_errors": [text], "message": text}


# --- Classroom 50 -----------------------------------------------------------------------

def _submission_instant(cwd):
    """The graded commit's committer date (Classroom 50's `datetime`: the submission
    instant, the same on a regrade), else now; both UTC, ISO 8601."""
    import subprocess
    try:
        stamp = subprocess.run(["git", "-C", str(cwd), "log", "-1", "--format=%ct"], capture_output=True,
                               text=True, timeout=20).stdout.strip()
        when = datetime.datetime.fromtimestamp(int(stamp), datetime.timezone.utc)
    except (OSError, ValueError, subprocess.SubprocessError):
        when = datetime.datetime.now(datetime.timezone.utc)
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def classroom50(out, labs, config, env, cwd="."):
    """Classroom 50's result.json (schema classroom50/result/v1) for `labs` of kit-grade's
    OUT folder. Scores are integers: a check's points from grading.json when it passed,
    else 0 (kit-grade's lab score is weight * passed points / all points, so the ratio is
    the same); kit-grade's own numbers travel in each test's "kit-grade" field."""
    summary = load_summary(out)
    tests = []
    for lab in labs:
        entry = summary["labs"].get(str(lab))
        points = check_points(config, lab)
        label = lab_label(lab, entry or {})
        checks = dict(ordered_checks(entry or {}, list(points)))
        status = (entry or {}).get("status", "error")
        for i, cid in enumerate(points):
            c = checks.get(cid, {})
            passed = bool(c.get("passed")) and status == "graded"
            test = {"test-name": f"{label}: {c.get('title', cid)}", "passed": passed,
                    "score": points[cid] if passed else 0, "max-score": points[cid],
                    "kit-grade": {"lab": int(lab), "check": cid, "status": status,
                                  "score": c.get("score", 0.0), "max_score": c.get("max_score", 0.0),
                                  "summary": c.get("summary", "")}}
            if status != "graded" and i == 0:
                test["kit-grade"]["message"] = (entry or {}).get("message", "not graded")
            if status == "graded" and not passed and (entry or {}).get("likely_text"):
                test["kit-grade"]["likely"] = entry["likely_text"]
            if status == "graded" and not passed and (entry or {}).get("functions_text"):
                test["kit-grade"]["functions"] = entry["functions_text"]
            tests.append(test)
    return {
        "schema": "classroom50/result/v1",
        "classroom": env.get("CLASSROOM", ""),
        "assignment": env.get("ASSIGNMENT", ""),
        "submission": env.get("SUBMISSION_TAG", ""),
        "commit": env.get("COMMIT_URL", ""),
        "release": env.get("RELEASE_URL", ""),
        "review": env.get("REVIEW_URL") or env.get("COMMIT_URL", ""),
        "datetime": _submission_instant(cwd),
        "score": sum(t["score"] for t in tests),
        "max-score": sum(t["max-score"] for t in tests),
        "tests": tests,
    }


def self_contained_report(out, dest):
    """OUT/report.html with its img/ pictures inlined: one file that shows the renders
    wherever it is opened (a release asset has no img/ beside it)."""
    out = Path(out)
    text = (out / "report.html").read_text(encoding="utf-8")

    def inline(m):
        path = out / html.unescape(m.group(2))
        if path.is_file() and path.resolve().is_relative_to(out.resolve()):
            return f'{m.group(1)}="{_data_url(path)}"'
        return m.group(0)

    Path(dest).write_text(re.sub(r'(src|href)="(img/[^"]+\.png)"', inline, text), encoding="utf-8")


# --- command line -----------------------------------------------------------------------

def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    folders = sub.add_parser("folders", help="the NN-name folders of the kit's labs, or of --labs")
    folders.add_argument("--kit", required=True, type=Path)
    folders.add_argument("--labs", default="")
    stage = sub.add_parser("stage", help="put a lab's loose files into NN-name/")
    stage.add_argument("--kit", required=True, type=Path)
    stage.add_argument("--lab", required=True, type=int)
    stage.add_argument("--submission", required=True, type=Path)
    stage.add_argument("--dest", required=True, type=Path)
    args = parser.parse_args(argv)
    if args.command == "folders":
        try:
            print("\n".join(lab_folders(args.kit, args.labs)))
        except LookupError as e:
            print(f"--labs: {e}", file=sys.stderr)
            return 1
        return 0
    if args.command == "stage":
        try:
            folder, files = lab_folder(args.kit, args.lab)
        except LookupError as e:
            print(f"platform_results: {e}", file=sys.stderr)
            return 0
        staged, found, missing = stage_loose(args.submission, folder, files, args.dest)
        if staged:
            if missing:
                print(f"platform_results: not uploaded: {', '.join(missing)}", file=sys.stderr)
            print(staged)
    return 0


if __name__ == "__main__":
    sys.exit(main())
