#!/usr/bin/env python3
"""./kit grade --self-check: does the grader catch plausible mistakes, and only those?

Every entry of instructor/grading/catalogue.json edits a copy of one lab's reference
solution (solutions/NN-name/) and grades that lab alone with kit-grade:

  * a "mistake" passes when it loses points (status graded, score < max);
  * an "equivalent" (correct, written differently) passes when it keeps full marks.

Before the entries, the unchanged solution of every lab involved is graded too
(rows "solution-unchanged"): it must get full marks, or every other row means
nothing.

A mistake may carry "known_gap": "why" when the kit's grader is known not to
catch it yet (too few pixels change for its tolerances, no check renders the
scene that shows it). It is still graded every time: while it is missed the row
reads GAP, which is listed but not a failure; once the grader catches it the
row reads OK and asks for the known_gap to be removed.

An entry may carry "retired": "why" when a change of the lab's equation took its find
text out of the solution (./kit rebaseline writes it for every STALE entry): it is
listed and not graded until it is rewritten against the new solution and the
"retired" removed.

Verdicts: OK; MISSED (a mistake kept full marks); FALSE-FAIL (an equivalent
lost points); PROBE-MISSED (a mistake made inside a probed function whose probe,
tools/grade/frames/function_probes.h, reports no difference); PROBE-FALSE (a probe reports a
difference for an equivalent or the unchanged solution); GAP (a mistake with a known_gap kept full marks); STALE (a `find`
text does not occur exactly once in the solution: the entry must be updated);
BROKEN (the edit does not compile, or grading ended in a status other than
graded, so the entry tests nothing); ERROR (kit-grade did not run or left no
summary.json).

The entries of one lab are graded by one `kit-grade --batch` run (--jobs at a
time), which saves a process start and the loading of the references per entry.

Exit status: 0 when no row failed (GAP rows do not fail), 1 when one did, 2 on
a usage or catalogue-file error.
"""

import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
KINDS = ("mistake", "equivalent")
REQUIRED = {"id": str, "lab": int, "kind": str, "description": str, "edits": list}


class CatalogueError(Exception):
    pass


def stage_labs():
    """The lab numbers of the stage table (common/render/stages.cpp), as its labs/NN-name folders."""
    return sorted(int(p.name[:2]) for p in (ROOT / "labs").iterdir() if p.is_dir() and re.match(r"\d\d-", p.name))


def load_catalogue(path):
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CatalogueError(f"catalogue not found: {path}")
    except json.JSONDecodeError as e:
        raise CatalogueError(f"{path} is not valid JSON: {e}")
    entries = data.get("entries") if isinstance(data, dict) else None
    if not isinstance(entries, list) or not entries:
        raise CatalogueError(f"{path}: expected an object with a non-empty 'entries' list")
    seen = set()
    labs = stage_labs()
    for i, e in enumerate(entries):
        where = f"{path}: entry {i + 1}" + (f" ('{e.get('id')}')" if isinstance(e, dict) and e.get("id") else "")
        if not isinstance(e, dict):
            raise CatalogueError(f"{where}: not an object")
        for key, typ in REQUIRED.items():
            if not isinstance(e.get(key), typ) or isinstance(e.get(key), bool):
                raise CatalogueError(f"{where}: '{key}' must be a {typ.__name__}")
        if not re.fullmatch(r"[a-z0-9][a-z0-9-]*", e["id"]):
            raise CatalogueError(f"{where}: id must be lower-case letters, digits and dashes")
        if e["id"] in seen:
            raise CatalogueError(f"{where}: duplicate id")
        seen.add(e["id"])
        if e["lab"] not in labs:
            raise CatalogueError(f"{where}: lab must be one of the stage table's ({', '.join(map(str, labs))})")
        if e["kind"] not in KINDS:
            raise CatalogueError(f"{where}: kind must be one of {', '.join(KINDS)}")
        if not e["edits"]:
            raise CatalogueError(f"{where}: needs at least one edit")
        family = e.get("family")
        if e["kind"] == "mistake" and not (isinstance(family, str) and re.fullmatch(r"[a-z0-9-]+\.[a-z0-9-]+", family)):
            raise CatalogueError(f"{where}: a mistake needs a 'family', PART.TERM (the same term of the same formula)")
        if "known_gap" in e and (e["kind"] != "mistake" or not isinstance(e["known_gap"], str) or not e["known_gap"]):
            raise CatalogueError(f"{where}: 'known_gap' is a non-empty reason, and only for mistakes")
        if "retired" in e and (not isinstance(e["retired"], str) or not e["retired"]):
            raise CatalogueError(f"{where}: 'retired' is a non-empty reason")
        for j, ed in enumerate(e["edits"]):
            if not isinstance(ed, dict) or not all(isinstance(ed.get(k), str) for k in ("file", "find", "replace")):
                raise CatalogueError(f"{where}: edit {j + 1} needs string 'file', 'find' and 'replace'")
            if not ed["find"]:
                raise CatalogueError(f"{where}: edit {j + 1} has an empty 'find'")
            if ed["find"] == ed["replace"]:
                raise CatalogueError(f"{where}: edit {j + 1} replaces a text with itself")
            if "/" in ed["file"] or ed["file"].startswith("."):
                raise CatalogueError(f"{where}: edit {j + 1}: 'file' is a file name inside the lab folder")
    return data


def lab_folder(solutions, lab):
    found = sorted(p for p in solutions.glob(f"{lab:02d}-*") if p.is_dir())
    if len(found) != 1:
        raise CatalogueError(f"expected one folder {solutions}/{lab:02d}-*, found {len(found)}")
    return found[0]


def snippet(text, width=70):
    one_line = text.replace("\n", "\\n")
    return one_line if len(one_line) <= width else one_line[: width - 3] + "..."


def apply_edits(entry, lab_dir):
    """The lab's files with the entry's edits applied, or raises CatalogueError naming the stale edit."""
    files = {p.name: p.read_text(encoding="utf-8") for p in lab_dir.iterdir() if p.is_file()}
    rel = f"solutions/{lab_dir.name}"
    for j, ed in enumerate(entry["edits"], 1):
        if ed["file"] not in files:
            raise CatalogueError(f"edit {j}: {rel}/{ed['file']} does not exist")
        count = files[ed["file"]].count(ed["find"])
        if count != 1:
            raise CatalogueError(
                f"edit {j}: the find text occurs {count} times in {rel}/{ed['file']} (must be exactly once; "
                f"the solution changed?): \"{snippet(ed['find'])}\"")
        files[ed["file"]] = files[ed["file"]].replace(ed["find"], ed["replace"])
    return files


class Row:
    def __init__(self, entry_id, lab, kind, description, known_gap=None, family=None):
        self.id, self.lab, self.kind, self.description = entry_id, lab, kind, description
        self.family = family or entry_id
        self.known_gap = known_gap
        self.score = self.max_score = None
        self.status = ""
        self.verdict = ""
        self.details = []  # lines printed under the table (failed rows, known gaps)
        self.signatures = {}  # check key -> signature, from summary.json (tools/grade/verdict/diagnosis.h)
        self.failed_checks = set()  # the keys of the checks it failed
        self.named = []       # the ids kit-grade named for this lab, closest first
        self.functions = []   # summary.json's probed functions (tools/grade/frames/function_probes.h)
        self.evidence = set()  # lab 7: the parts its counts name (summary.json "evidence")
        self.edited_functions = set()  # the functions of probed files its edits lie in
        self.result = None    # kit-grade's result folder for it, kept until the run ends (name_again reads it)

    @property
    def passed(self):
        return self.verdict == "OK"

    @property
    def failed(self):
        return self.verdict not in ("OK", "GAP")


def write_submission(folder, lab_name, files):
    (folder / lab_name).mkdir(parents=True)
    for name, text in files.items():
        (folder / lab_name / name).write_text(text, encoding="utf-8")


def cpu_limit_args(args):
    """kit-grade's --cpu-limit where one was given (softpipe needs minutes for lab 6's maps)."""
    return ["--cpu-limit", str(args.cpu_limit), "--timeout", str(2 * args.cpu_limit)] if args.cpu_limit else []


def run_kit_grade(cmd, timeout):
    """(exit status, output tail) of one kit-grade run; status None when it ran over `timeout`."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, [f"kit-grade ran over {timeout} s: {' '.join(cmd)}"]
    except OSError as e:
        return -1, [f"cannot run kit-grade: {e}"]
    tail = (proc.stderr + proc.stdout).strip().splitlines()[-8:]
    return proc.returncode, [f"kit-grade exited {proc.returncode}: {' '.join(cmd)}"] + tail


def grade_lab_batch(lab, jobs, args, work):
    """All of one lab's rows in one `kit-grade --batch` run (saves a process start per row)."""
    batch, out = work / f"lab{lab}" / "submissions", work / f"lab{lab}" / "results"
    for row, files, lab_name in jobs:
        write_submission(batch / row.id, lab_name, files)
    out.mkdir(parents=True)
    cmd = [str(args.kit_grade), "--batch", str(batch), "--labs", str(lab), "--out", str(out),
           "--jobs", str(args.jobs)] + cpu_limit_args(args)
    status, tail = run_kit_grade(cmd, args.timeout + 10 * len(jobs))
    for row, _, _ in jobs:
        judge(row, out / row.id, status, tail, args, batch / row.id)


def grade_one(row, files, lab_name, args, work):
    """One row, one `kit-grade SUBMISSION` run (--no-batch)."""
    folder = work / f"lab{row.lab}-{row.id}"
    write_submission(folder / "submission", lab_name, files)
    out = folder / "result"
    out.mkdir(parents=True)
    cmd = [str(args.kit_grade), str(folder / "submission"), "--labs", str(row.lab), "--out", str(out), "--jobs", "1"]
    cmd += cpu_limit_args(args)
    status, tail = run_kit_grade(cmd, args.timeout)
    judge(row, out, status, tail, args, folder / "submission")


def grade_jobs(jobs, args, work):
    """Grades every job, one kit-grade --batch run per lab (or one run per row with --no-batch), in
    `work`; judge reads each row's result."""
    try:
        by_lab = {}
        for job in jobs:
            by_lab.setdefault(job[0].lab, []).append(job)
        for lab, lab_jobs in sorted(by_lab.items()):
            if sys.stderr.isatty():
                print(f"self-check: lab {lab}: grading {len(lab_jobs)} submissions", file=sys.stderr, flush=True)
            if args.no_batch:
                with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
                    list(pool.map(lambda j: grade_one(*j, args, work), lab_jobs))
            else:
                grade_lab_batch(lab, lab_jobs, args, work)
    except Exception as e:  # a bug or a full disk must still end in a table that says so
        for row, _, _ in jobs:
            if not row.verdict:
                row.verdict = "ERROR"
                row.details = [f"self-check stopped: {type(e).__name__}: {e}"]


def name_again(rows, args):
    """Each row's names as kit-grade gives them with the mistakes.json written since the rows were
    graded: `kit-grade --name-again` reads what their grading named them from (naming.json in each
    result folder, tools/grade/verdict/diagnosis.h) and renders nothing."""
    cmd = [str(args.kit_grade), "--name-again"] + [str(r.result) for r in rows]
    status, tail = None, []
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
        status, tail = proc.returncode, proc.stderr.strip().splitlines()[-4:]
        names = json.loads(proc.stdout) if status == 0 else None
    except (OSError, subprocess.TimeoutExpired, ValueError) as e:
        names, tail = None, [f"{type(e).__name__}: {e}"]
    for r in rows:
        if names is None:
            r.details.append(f"named again, kit-grade gave none (exit {status}): {' '.join(tail)}")
        else:
            r.named = [m.get("id") for m in names.get(str(r.result), {}).get(str(r.lab), [])]


def judge(row, out, status, tail, args, submission):
    """Fills row's score and verdict from kit-grade's files in `out`."""
    row.result = out
    summary_path = out / "summary.json"
    if status != 0 or not summary_path.exists():
        row.verdict = "ERROR"
        row.details = ([] if summary_path.exists() else [f"no {summary_path}"]) + tail
        return
    try:
        lab = json.loads(summary_path.read_text())["labs"][str(row.lab)]
        row.score, row.max_score, row.status = float(lab["score"]), float(lab["max_score"]), lab["status"]
    except (ValueError, KeyError, TypeError) as e:
        row.verdict = "ERROR"
        row.details = [f"summary.json has no usable labs.{row.lab} entry ({e}): {summary_path}"]
        return
    row.signatures = {key: c.get("signature") or [] for key, c in lab.get("checks", {}).items()}
    row.failed_checks = {key for key, c in lab.get("checks", {}).items() if not c.get("passed")}
    row.named = [m.get("id") for m in lab.get("likely_mistakes", [])]
    row.functions = lab.get("functions", [])
    row.evidence = set(lab.get("evidence", []))
    tests = []
    try:
        tests = json.loads((out / "results.json").read_text()).get("tests", [])
    except (OSError, ValueError):
        pass
    full = row.score >= row.max_score - 1e-9 and row.max_score > 0
    if row.status != "graded":
        row.verdict = "BROKEN"
        message = lab.get("message", "") if isinstance(lab, dict) else ""
        row.details = [f"grading ended with status '{row.status}', so this entry tests nothing "
                       "(an edit that does not compile?)"] + [f"  {line}" for line in str(message).splitlines()[:6]]
    elif row.kind == "starter":
        row.verdict = "OK"  # graded for its signatures only
    elif row.kind == "mistake":
        row.verdict = ("GAP" if row.known_gap else "MISSED") if full else "OK"
        if full and row.known_gap:
            row.details = [f"known gap: {row.known_gap}"]
        elif not full and row.known_gap:
            row.details = ["detected now: remove this entry's known_gap from the catalogue"]
        elif full:
            row.details = ["every test passed; the tests of this lab:"] + [
                f"  {t.get('name')}: {t.get('score')}/{t.get('max_score')}" for t in lab_tests(tests, row.lab)]
    else:
        row.verdict = "OK" if full else "FALSE-FAIL"
        if not full:
            row.details = failing_tests(tests, row.lab, limit=6)
    if row.verdict in ("OK", "GAP"):
        judge_probes(row)
    if args.keep:
        row.details.append(f"kept: {submission} -> {out}")


# --- Function probes (tools/grade/frames/function_probes.h) -------------------------------------------
DEFINITION = re.compile(r"^[ \t]*(?:void|vec[234]|float|int|bool|mat[234]|Light)[ \t]+(\w+)[ \t]*\([^)]*\)[ \t]*\{", re.M)


def enclosing_function(text, position):
    """The name of the GLSL function whose body holds `position` in `text`, or None."""
    for m in DEFINITION.finditer(text):
        if m.start() > position:
            break
        depth, i = 0, m.end() - 1
        while i < len(text):
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            if depth == 0:
                break
            i += 1
        if m.end() <= position < i:
            return m.group(1)
    return None


def edited_functions(entry, lab_dir):
    """(file, function) of every edit of `entry` that lies inside a function of the solution."""
    out = set()
    for ed in entry["edits"]:
        path = lab_dir / ed["file"]
        text = path.read_text(encoding="utf-8") if path.is_file() else ""
        name = enclosing_function(text, text.find(ed["find"])) if ed["find"] in text else None
        if name:
            out.add((ed["file"], name))
    return out


def probed_in(row):
    """The row's edited functions that kit-grade probes: {(file, function)}."""
    probed = {(f.get("file"), f.get("function")) for f in row.functions}
    return row.edited_functions & probed


def judge_probes(row):
    """A mistake inside a probed function: the probe must report it, with inputs. An equivalent (or the
    unchanged solution): no probe may report a difference."""
    differing = [f for f in row.functions if f.get("status") == "differs"]
    if row.kind == "mistake":
        for file, function in sorted(probed_in(row)):
            if not any(f.get("function") == function and f.get("file") == file and f.get("first") for f in differing):
                row.verdict = "PROBE-MISSED"
                row.details = [f"the edit lies in {file}'s {function}, whose probe reports no difference"] + [
                    f"  {f.get('message')}" for f in row.functions if f.get("function") == function]
    elif row.kind == "equivalent" and differing:
        row.verdict = "PROBE-FALSE"
        row.details = ["a probe reports a difference for a correct lab:"] + [f"  {f.get('message')}" for f in differing]


def probe_figures(rows):
    """The issue's probe targets, as the self-check prints them."""
    pinned = [r for r in rows if r.kind == "mistake" and r.status == "graded" and probed_in(r)]
    named = [r for r in pinned if r.verdict != "PROBE-MISSED"]
    correct = [r for r in rows if r.kind == "equivalent" and r.status == "graded" and r.functions]
    quiet = [r for r in correct if r.verdict != "PROBE-FALSE"]
    return (f"function probes: the failing function named, with inputs, for {len(named)}/{len(pinned)} mistakes made "
            f"in a probed function; no difference reported for {len(quiet)}/{len(correct)} equivalents and "
            f"unchanged solutions of probed labs")


def lab_tests(tests, lab):
    """This lab's tests (names conventionally mention the lab); all tests when none do."""
    mine = [t for t in tests if re.search(rf"(?i)\blab\s*0?{lab}\b|\b0{lab}-", str(t.get("name", "")))]
    return mine or tests


def plain(test):
    """A test's output as text (kit-grade writes Markdown: drop its backslash escapes)."""
    text = str(test.get("output", ""))
    if test.get("output_format") == "md":
        text = re.sub(r"\\([\\`*_{}\[\]()#+\-.!|%<>~])", r"\1", text)
    return text


def failing_tests(tests, lab, limit):
    lines = []
    for t in lab_tests(tests, lab):
        try:
            lost = float(t.get("score", 0)) < float(t.get("max_score", 0)) - 1e-9
        except (TypeError, ValueError):
            lost = True
        if lost:
            first = (plain(t).strip().splitlines() or [""])[0]
            lines.append(f"  {t.get('name')}: {t.get('score')}/{t.get('max_score')}  {snippet(first, 110)}")
    if len(lines) > limit:
        lines = lines[:limit] + [f"  ... and {len(lines) - limit} more"]
    return lines


def fmt_score(row):
    if row.score is None:
        return "-"
    return f"{row.score:g}/{row.max_score:g}"


def print_table(rows, wide):
    desc_width = 10_000 if wide else 60
    def cut(s):
        return s if len(s) <= desc_width else s[: desc_width - 3] + "..."
    header = ("id", "lab", "kind", "description", "score/max", "verdict")
    cells = [header] + [(r.id, str(r.lab), r.kind, cut(r.description), fmt_score(r), r.verdict) for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(header))]
    def line(c):
        return " | ".join(c[i].ljust(widths[i]) if i < len(c) - 1 else c[i] for i in range(len(c)))
    print(line(header))
    print("-+-".join("-" * w for w in widths))
    for c in cells[1:]:
        print(line(c))


def write_entry(entries, entry_id, dest, solutions):
    """--write: entry_id's lab folder with its edits applied, as DEST/NN-name/; 0, or 2 with a message."""
    found = [e for e in entries if e["id"] == entry_id]
    try:
        if not found:
            raise CatalogueError(f"no catalogue entry '{entry_id}'")
        lab_dir = lab_folder(solutions, found[0]["lab"])
        write_submission(dest, lab_dir.name, apply_edits(found[0], lab_dir))
    except (CatalogueError, OSError) as e:
        print(f"self-check: {e}", file=sys.stderr)
        return 2
    return 0


# --- Naming the mistake (tools/grade/verdict/diagnosis.h) -------------------------------------------
SIGNATURE_CAP = 4.0  # compare.h kSignatureCap
STEPS = 255          # the file's integers (diagnosis.h)
FAILED_WEIGHT = 0.5  # diagnosis.h kFailedWeight
MIN_NAMED = 0.1      # diagnosis.h kMinNamedSimilarity


def encoded(signatures):
    """The file's integers: round(STEPS x sqrt(tile / cap)) (diagnosis.h check_features)."""
    return {key: [round(STEPS * (min(max(x, 0.0), SIGNATURE_CAP) / SIGNATURE_CAP) ** 0.5) for x in v]
            for key, v in signatures.items()}


def features(signatures, failed_checks):
    """diagnosis.cpp, a stored mistake's features: each check's integers / STEPS, then its failed flag."""
    return {key: [q / STEPS for q in v] + [FAILED_WEIGHT if key in failed_checks else 0.0]
            for key, v in encoded(signatures).items()}


def similarity(a, b):
    """diagnosis.cpp signature_similarity: the cosine of the checks' features, concatenated; a check whose
    features are longer on one side is compared over the signature both have and the failed flag."""
    dot = aa = bb = 0.0
    for key in a.keys() | b.keys():
        va, vb = a.get(key, []), b.get(key, [])
        if va and vb and len(va) != len(vb):
            n = min(len(va), len(vb))
            va, vb = va[:n - 1] + va[-1:], vb[:n - 1] + vb[-1:]
        dot += sum(x * y for x, y in zip(va, vb))
        aa += sum(x * x for x in va)
        bb += sum(x * x for x in vb)
    return dot / (aa * bb) ** 0.5 if aa > 0 and bb > 0 else 0.0


def write_signatures(path, rows, labs=None):
    """Writes the rows' signatures to PATH; with LABS (self-check --lab), those of the other labs are kept from the
    file as it was. The file is left as it is, byte for byte, when its text would not change. Returns the labs
    whose entries changed."""
    mistakes = [dict({"id": r.id, "lab": r.lab, "description": r.description, "family": r.family,
                      "signatures": encoded(r.signatures), "failed": sorted(r.failed_checks)},
                     **({"functions": sorted(differing_functions(r))} if probed_lab(r) else {}))
                for r in rows]
    if labs and path.is_file():
        try:
            kept = json.loads(path.read_text()).get("mistakes", [])
        except ValueError:
            kept = []
        mistakes += [m for m in kept if m.get("lab") not in labs]
    mistakes.sort(key=lambda m: (m["lab"], m["id"]))
    doc = {"about": "Where each catalogued mistake's error lies, check by check (tools/grade/diagnosis.h): written by "
                    "`kit grade --self-check --write-signatures`; kit-grade names the closest for a failed lab.",
           "mistakes": mistakes}
    text = json.dumps(doc, separators=(",", ":")) + "\n"
    try:
        before = json.loads(path.read_text()).get("mistakes", []) if path.is_file() else []
    except ValueError:
        before = []
    if path.is_file() and path.read_text() == text:
        print(f"self-check: {len(mistakes)} mistakes' signatures unchanged in {path}")
        return set()
    path.write_text(text)
    print(f"self-check: {len(mistakes)} mistakes' signatures written to {path}")
    by_lab = lambda ms, lab: [m for m in ms if m.get("lab") == lab]
    return {lab for lab in {m.get("lab") for m in mistakes + before} if by_lab(mistakes, lab) != by_lab(before, lab)}


# What to do about a row that needs attention, for an instructor who has just changed a lab
# (./kit rebaseline prints these; instructor/changing_a_lab/README.md explains them).
NEXT_STEPS = {
    "MISSED": "the mistake keeps full marks now. If the lab's new equation makes it correct, make the entry an "
              "\"equivalent\" (or remove it); if it should still lose points, find a scene that shows it "
              "(tools/scenes/scene_catalogue.cpp, a check in tools/grade/frames/checks.cpp), or, where it only just passes, "
              "tighten that check's tolerance in tools/grade/grading.json; else give it a \"known_gap\" saying why",
    "FALSE-FAIL": "this equivalent loses points now: under the new equation it is no longer the same; make it a "
                  "\"mistake\" with a family, or change its replace text to what is equivalent now",
    "STALE": "its find text is no longer in the solution: rewrite the entry's edits against the new solution, "
             "or remove the entry where the mistake cannot be made any more",
    "PROBE-MISSED": "the mistake lies in a probed function, but its probe (tools/grade/frames/function_probes.cpp) reports "
                    "no difference: add inputs to the probe's table that show it, then ./kit rebaseline",
    "PROBE-FALSE": "a probe reports a difference for a correct lab: the probe's inputs reach a case where correct "
                   "functions may differ (a guard's floor, an ill-conditioned value); mark such cases finite_only or "
                   "leave them out of tools/grade/frames/function_probes.cpp, then ./kit rebaseline",
    "BROKEN": "the edited solution does not compile or render: rewrite the entry's replace text against the "
              "new solution",
    "ERROR": "kit-grade did not run: see the lines above (is the build current? ./kit setup)",
}


def next_step(row):
    if row.verdict == "OK" and row.known_gap and row.score is not None and row.score < row.max_score:
        return "caught now: remove the entry's \"known_gap\""
    return NEXT_STEPS.get(row.verdict, "")


def write_json(path, rows, started, naming):
    """The rows as JSON (./kit rebaseline and handout_figures.py read it): verdict, score, next step;
    and the naming measures (naming_counts, None where no mistake was caught)."""
    doc = {"seconds": round(time.monotonic() - started, 1),
           "naming": naming,
           "rows": [{"id": r.id, "lab": r.lab, "kind": r.kind, "verdict": r.verdict, "score": r.score,
                     "max_score": r.max_score, "known_gap": r.known_gap, "named": r.named,
                     "details": r.details, "next_step": next_step(r)} for r in rows]}
    path.parent.mkdir(parents=True, exist_ok=True)  # a fresh build's test-tmp/, say
    path.write_text(json.dumps(doc, indent=1) + "\n")


def differing_functions(row):
    """The probed parts (tools/grade/frames/function_probes.h, FunctionProbe::part: a function, a pass's file, or
    "FILE, TERM" for a part of a pass) that differ for the row, a term a term probe decided where a called
    function explains it, and lab 7's parts from its counts (summary.json's "evidence":
    tools/grade/verdict/compare.h, volume_evidence_parts)."""
    return ({f.get("part", f.get("function")) for f in row.functions
             if f.get("status") == "differs" or (f.get("status") == "explained" and ", " in f.get("part", ""))}
            | getattr(row, "evidence", set()))


def probed_lab(row):
    """Whether every probe of the row's lab ran (kit-grade goes by the probes then)."""
    return bool(row.functions) and all(f.get("status") != "not_run" for f in row.functions)


PROBE_WEIGHT = 0.1   # diagnosis.h kProbeWeight
PASS_PROBE_WEIGHT = 1.0   # diagnosis.h kPassProbeWeight: where the lab's probes are passes (function "main")
TERM_PROBE_WEIGHT = 1.0   # diagnosis.h kTermProbeWeight: where a term probe's decided term ("cook_torrance, fresnel") differs


def probe_agreement(row, candidate):
    """diagnosis.cpp probe_agreement: the Jaccard index of the two differing-function sets (1 when both
    are empty), 0 without probes."""
    if row.functions is None or candidate.functions is None:
        return 0.0
    union = row.functions | candidate.functions
    return len(row.functions & candidate.functions) / len(union) if union else 1.0


def term_names_family(row, candidate):
    """diagnosis.cpp term_names_family: a term probe's decided term (a differing part "FUNCTION, TERM")
    is the TERM of the candidate's family (LAB-PART.TERM)."""
    term = candidate.family.rsplit(".", 1)[1] if "." in candidate.family else None
    return term is not None and any(f.split(", ", 1)[1] == term for f in row.functions or () if ", " in f)


def decided_term(row):
    """diagnosis.cpp likely_mistakes: a term probe's decided term ("FUNCTION, TERM") is among the row's
    differing parts, in a lab whose probes are functions, not passes."""
    return not getattr(row, "passes", False) and any(", " in f for f in row.functions or ())


def placed(row, candidate):
    """The candidate's family's term is the term a term probe decided for row (named even below MIN_NAMED)."""
    return decided_term(row) and term_names_family(row, candidate)


def ranked(row, candidates):
    """candidates (same lab, not row) as kit-grade ranks them for row (diagnosis.cpp likely_mistakes):
    similarity plus the probes' share, closest first, as (similarity, row)."""
    scored = [(similarity(row.features, c.features), c) for c in candidates if c.lab == row.lab and c is not row]
    if row.lab == 7:  # diagnosis.h: lab 7 ranks by the parts first, the images only between equals
        return sorted(scored, key=lambda t: (-probe_agreement(row, t[1]), -t[0]))
    passes = getattr(row, "passes", False)
    terms = decided_term(row)
    weight = PASS_PROBE_WEIGHT if passes else TERM_PROBE_WEIGHT if terms else PROBE_WEIGHT
    return sorted(scored, key=lambda t: -(t[0] + weight * ((1.0 if term_names_family(row, t[1]) else 0.0) if terms
                                                            else probe_agreement(row, t[1]))))


def naming_counts(caught):
    """The naming measures as numbers (handout_figures.py checks the handouts' against them): named
    first with every signature in; with each left out, a relative (its family) named first or within
    the first three, in all and by lab; and the mistakes whose family is not named first."""
    # The rows' features as kit-grade reads them from the file, each ranked once.
    stored = [types.SimpleNamespace(id=r.id, lab=r.lab, family=r.family,
                                    features=features(r.signatures, r.failed_checks),
                                    functions=differing_functions(r) if probed_lab(r) else None,
                                    passes=any(f.get("function") == "main" for f in r.functions)) for r in caught]
    scores = {r.id: ranked(r, stored) for r in stored}
    with_relatives = [r for r in stored if any(o.family == r.family for o in stored if o is not r)]
    counts = {"caught": len(caught), "with_relatives": len(with_relatives), "first": 0, "within_three": 0,
              "named_right": sum(1 for r in caught if r.named and r.named[0] == r.id),
              "distinct": sum(1 for r in stored if all(s < 0.999 for s, _ in scores[r.id])),
              "by_lab": {}, "misses": []}
    for r in with_relatives:
        # Named even below the floor (diagnosis.h): a mistake a decided term places, and in lab 7 one that
        # shares a part with the row's.
        fams = list(dict.fromkeys(o.family for s, o in scores[r.id]
                                  if s >= MIN_NAMED or placed(r, o)
                                  or (r.lab == 7 and r.functions and probe_agreement(r, o) > 0)))[:3]  # one per family
        first, within = bool(fams) and fams[0] == r.family, r.family in fams
        counts["first"] += first
        counts["within_three"] += within
        lab = counts["by_lab"].setdefault(str(r.lab), {"first": 0, "within_three": 0, "with_relatives": 0})
        lab["first"] += first
        lab["within_three"] += within
        lab["with_relatives"] += 1
        if not first:
            counts["misses"].append(f"lab {r.lab}: {r.id} ({r.family}): named {', '.join(fams) or 'nothing'}")
    return counts


def naming_figures(c, detail=False):
    """The naming measures (naming_counts) in words, as the self-check prints them; with `detail`,
    then by lab and each mistake whose family is not named first."""
    text = (f"naming: {c['caught']} caught mistakes; with every signature in, named first by its own: "
            f"{c['distinct']}/{c['caught']} have signatures unlike any other's (a duplicate ties); kit-grade named the "
            f"right one first for {c['named_right']}/{c['caught']} (with the mistakes.json it read); "
            f"each left out: a mistake of its family named first for {c['first']}/{c['with_relatives']}, within the first "
            f"three named (one per family) for {c['within_three']}/{c['with_relatives']} (families: the catalogue's)")
    if detail:
        text += "".join(f"\n  lab {lab}: first {v['first']}/{v['with_relatives']}, within three "
                        f"{v['within_three']}/{v['with_relatives']}" for lab, v in sorted(c["by_lab"].items()))
        text += "\nnot named first, each left out:\n" + "\n".join("  " + m for m in c["misses"])
    return text


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="kit grade --self-check",
        description="Grades every entry of the mistake catalogue and prints the detection table.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=textwrap.dedent("""\
            verdicts: OK, MISSED (mistake kept full marks), FALSE-FAIL (equivalent lost points),
                      GAP (mistake with a known_gap kept full marks: listed, not a failure),
                      STALE (find text not exactly once), BROKEN (status not graded), ERROR (kit-grade failed),
                      PROBE-MISSED (a mistake in a probed function its probe did not report),
                      PROBE-FALSE (a probe reported a difference for a correct lab)"""))
    parser.add_argument("--kit-grade", type=Path, default=ROOT / "build" / "default" / "tools" / "kit-grade",
                        help="the grader binary (default: build/default/tools/kit-grade)")
    parser.add_argument("--catalogue", type=Path, default=ROOT / "instructor" / "grading" / "catalogue.json",
                        help="the catalogue (default: instructor/grading/catalogue.json)")
    parser.add_argument("--solutions", type=Path, default=ROOT / "solutions",
                        help="the reference solutions the edits apply to (default: solutions/)")
    parser.add_argument("--jobs", type=int, default=2, help="entries graded at the same time (default 2)")
    parser.add_argument("--no-batch", action="store_true",
                        help="one kit-grade run per entry instead of one --batch run per lab (slower)")
    parser.add_argument("--lab", type=int, action="append", help="only this lab (repeatable)")
    parser.add_argument("--only", action="append", metavar="TEXT", help="only entries whose id contains TEXT (repeatable)")
    parser.add_argument("--validate", action="store_true",
                        help="only check the catalogue against the solutions (no grading, no kit-grade needed)")
    parser.add_argument("--no-baseline", action="store_true", help="skip grading the unchanged solutions")
    parser.add_argument("--cpu-limit", type=int, default=0, metavar="S",
                        help="kit-grade's --cpu-limit for each lab (default: kit-grade's own); softpipe "
                             "(GALLIUM_DRIVER=softpipe) takes minutes of CPU for lab 6's maps")
    parser.add_argument("--timeout", type=int, default=300,
                        help="seconds one kit-grade run may take, plus 10 s per entry in a batch (default 300)")
    parser.add_argument("--keep", action="store_true", help="keep the submissions and results (paths are printed)")
    parser.add_argument("--wide", action="store_true", help="do not shorten descriptions")
    parser.add_argument("--naming-detail", action="store_true",
                        help="the naming measure by lab, and each mistake whose family is not named first")
    parser.add_argument("--write-signatures", type=Path, metavar="FILE",
                        help="write each caught mistake's signatures to FILE (tools/grade/references/mistakes.json"
                             " is the grader's) and print how well they name the mistakes")
    parser.add_argument("--json", type=Path, metavar="FILE",
                        help="also write the rows (verdict, score, next step) to FILE as JSON")
    parser.add_argument("--write", nargs=2, metavar=("ID", "DIR"),
                        help="only write entry ID's lab folder, edits applied, to DIR/NN-name/ (no grading; "
                             "instructor/handout_images.sh shows mistakes this way)")
    args = parser.parse_args(argv)

    started = time.monotonic()
    try:
        catalogue = load_catalogue(args.catalogue)
    except CatalogueError as e:
        print(f"self-check: {e}", file=sys.stderr)
        return 2
    entries = catalogue["entries"]
    if args.write:
        return write_entry(entries, args.write[0], Path(args.write[1]), args.solutions)
    # An entry ./kit rebaseline retired (its find text left the solution with a change of the
    # lab's equation) is not graded until it is rewritten and its "retired" removed.
    retired = [e for e in entries if e.get("retired")]
    entries = [e for e in entries if not e.get("retired")]
    if args.lab:
        entries = [e for e in entries if e["lab"] in args.lab]
    if args.only:
        entries = [e for e in entries if any(s in e["id"] for s in args.only)]
    if not entries:
        print("self-check: no catalogue entry matches the filters", file=sys.stderr)
        return 2

    # Apply every edit first: stale entries are reported without grading anything.
    rows, jobs = [], []
    labs = sorted({e["lab"] for e in entries})
    try:
        lab_dirs = {lab: lab_folder(args.solutions, lab) for lab in labs}
    except CatalogueError as e:
        print(f"self-check: {e}", file=sys.stderr)
        return 2
    if not args.no_baseline and not args.validate:
        for lab in labs:
            row = Row("solution-unchanged", lab, "equivalent", f"the reference solution of lab {lab}, unchanged")
            files = {p.name: p.read_text(encoding="utf-8") for p in lab_dirs[lab].iterdir() if p.is_file()}
            rows.append(row)
            jobs.append((row, files, lab_dirs[lab].name))
    if args.write_signatures:  # the starters too: a starter handed in is named as one
        for lab in labs:
            starter = ROOT / "labs" / lab_dirs[lab].name
            if starter.is_dir():
                row = Row(f"starter-lab{lab}", lab, "starter", "the starter as handed out: its TODOs are still to do")
                rows.append(row)
                jobs.append((row, {p.name: p.read_text(encoding="utf-8") for p in starter.iterdir() if p.is_file()},
                             lab_dirs[lab].name))
    for e in entries:
        row = Row(e["id"], e["lab"], e["kind"], e["description"], e.get("known_gap"), e.get("family"))
        row.edited_functions = edited_functions(e, lab_dirs[e["lab"]])
        rows.append(row)
        try:
            files = apply_edits(e, lab_dirs[e["lab"]])
        except CatalogueError as err:
            row.verdict = "STALE"
            row.details = [f"stale catalogue entry: {err}"]
            continue
        if args.validate:
            row.verdict = "OK"
        else:
            jobs.append((row, files, lab_dirs[e["lab"]].name))

    # The results stay until the signatures are written: name_again reads them.
    work = Path(tempfile.mkdtemp(prefix="kit-self-check-"))
    try:
        if jobs:
            if not args.kit_grade.is_file() or not os.access(args.kit_grade, os.X_OK):
                print(f"self-check: kit-grade not found at {args.kit_grade} (build it with ./kit setup, "
                      "or pass --kit-grade PATH)", file=sys.stderr)
                return 2
            grade_jobs(jobs, args, work)

        print_table(rows, args.wide)
        if retired:
            print(f"\nretired, not graded ({len(retired)}): " + ", ".join(e["id"] for e in retired)
                  + " (rewrite each against the new solution and remove its \"retired\", or delete it)")
        caught = [r for r in rows if r.kind == "mistake" and r.passed and r.status == "graded"]
        if args.write_signatures:
            changed = write_signatures(args.write_signatures,
                                       [r for r in rows if r.kind in ("mistake", "starter") and r.passed
                                        and r.status == "graded"], args.lab)
            # kit-grade named each mistake from the signatures as they were: the naming figures
            # (named_right) want the names it gives with the new ones. A lab's names come from its
            # own entries only (diagnosis.cpp), so only its caught mistakes are named again.
            again = [r for r in caught if r.lab in changed and r.result]
            if again:
                print(f"self-check: the signatures of lab{'s' if len(changed) > 1 else ''} "
                      f"{', '.join(map(str, sorted(changed)))} changed: their {len(again)} caught mistakes named "
                      "again as kit-grade names them now (kit-grade --name-again)")
                name_again(again, args)
    finally:
        if args.keep:
            print(f"self-check: submissions and results kept in {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    naming = naming_counts(caught) if caught else None
    if naming:
        print()
        print(naming_figures(naming, args.naming_detail))
    if any(r.functions for r in rows):
        print(probe_figures(rows))
    failed = [r for r in rows if r.failed]
    noted = [r for r in rows if r.failed or r.verdict == "GAP" or (r.known_gap and r.verdict == "OK" and r.score is not None)]
    if noted:
        print()
        for r in noted:
            print(f"{r.verdict}: {r.id} (lab {r.lab}, {r.kind}) {fmt_score(r)}")
            for d in r.details:
                print(f"    {d}")
            if next_step(r):
                print(f"    next step: {next_step(r)}")
    undetectable = catalogue.get("not_detectable", [])
    if undetectable and not args.only:
        shown = [u for u in undetectable if not args.lab or u.get("lab") in args.lab]
        if shown:
            print(f"\nNot in the catalogue because the kit's scenes cannot show them ({len(shown)}):")
            for u in shown:
                print(f"  lab {u.get('lab')}: {u.get('id')}: {u.get('reason')}")
    mistakes = [r for r in rows if r.kind == "mistake"]
    equivalents = [r for r in rows if r.kind == "equivalent"]
    if args.json:
        write_json(args.json, rows, started, naming)
    print()
    if args.validate:
        print(f"{len(rows) - len(failed)} passed, {len(failed)} failed (catalogue check only: entries whose edits"
              f" apply exactly once to {args.solutions}; nothing was graded)")
    else:
        gaps = sum(r.verdict == "GAP" for r in rows)
        print(f"{sum(r.passed for r in rows)} passed, {len(failed)} failed")
        print(f"({sum(r.passed for r in mistakes)}/{len(mistakes)} mistakes detected"
              f"{f', {gaps} known gaps not counted' if gaps else ''},"
              f" {sum(r.passed for r in equivalents)}/{len(equivalents)} equivalents at full marks;"
              f" {time.monotonic() - started:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
