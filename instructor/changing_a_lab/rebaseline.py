#!/usr/bin/env python3
"""./kit rebaseline [--labs N[,M...]] [--no-tests]: re-makes what follows from a change to a lab's
solution, equation or checks, in the order each step needs, and reports what changed and what
needs a decision (instructor/changing_a_lab/README.md explains every line).

  1. the labs' contracts (tools/grade/lab_contract.py): tools/grade/lab_functions.json follows the
     starters (a function they no longer declare leaves it; one declared anew, or with another
     signature, enters at default inputs to review), and the probe shaders are written from it;
  2. references: kit-grade --update-references (the solutions rendered again, the filter
     allowances with them); a file whose pixels did not change is kept byte for byte;
  3. the self-check with signatures (./kit grade --self-check --write-signatures): the catalogue
     graded against the new solutions, every lab's: the changed labs, every later one (they are
     assembled on them, common/render/stages.h), and the earlier ones too, since the naming
     figures the instructors' page quotes (naming.*) measure the whole catalogue;
  4. the handout figures that follow from grading (instructor/handout_figures.py), written again;
  5. the handout images (./kit handout-images); an image whose bytes did not change is kept;
  6. the calls between labs (which lab's solution calls which other lab's functions), the
     table in instructor/changing_a_lab/README.md written again;
  7. the quick tests (./kit test --quick, which builds what they need, the browser site too),
     unless --no-tests.

Then the report: the files each step changed, the catalogue entries that now need a decision
with the next step for each, the handout figures that changed, and the tests' verdict.
Exit status 0 when every step ran and nothing needs a decision, 1 otherwise.

    rebaseline.py --calls-table     print the calls table alone (Markdown)
    rebaseline.py --build DIR       the programs of another build of the kit (default: this kit's
                                    build/default); they read this kit's files (KIT_ROOT)
"""
import argparse
import hashlib
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
WATCHED = {"references": ROOT / "tools/grade/references", "handout images": ROOT / "handouts/images"}
CALLS_DOC = ROOT / "instructor" / "changing_a_lab" / "README.md"
CALLS_BEGIN, CALLS_END = "<!-- calls table: written by ./kit rebaseline -->", "<!-- /calls table -->"


def stage_table():
    """[(number, folder, [files])] from common/render/stages.cpp's kStages rows."""
    text = (ROOT / "common/render/stages.cpp").read_text(encoding="utf-8")
    rows = re.findall(r'\{(\d+), "[a-z]+", "(\d\d-[a-z]+)", \{([^}]*)\}', text)
    return [(int(n), folder, re.findall(r'"([^"]+)"', files)) for n, folder, files in rows]


# A GLSL function definition at the start of a line: return type, name, parameters, brace.
DEFINITION = re.compile(r"^(?:float|vec[234]|int|bool|mat[234]|void)\s+([a-z_][a-z0-9_]*)\s*\([^;{]*\)\s*\{", re.M)


def calls_table():
    """For each lab's solution file that calls a function of another lab's file, (lab, its file, the
    other lab, that file, [functions]), from the solutions' own text: which function each file
    defines, and where another lab's file calls it. The call reaches that lab's solution in the
    stages from the later of the two on (stage_library); before, the framework's stand-in in
    shaders/ where there is one (lab 2 calls light_radiance, which lab 3 writes)."""
    stages = stage_table()
    defined = {}  # function -> (lab, file)
    for number, folder, files in stages:
        for name in files:
            path = ROOT / "solutions" / folder / name
            if path.is_file():
                for function in DEFINITION.findall(path.read_text(encoding="utf-8")):
                    if function != "main":
                        defined.setdefault(function, (number, name))
    def calls_in(path, number):
        """Rows for the functions of other labs that the file at PATH (lab NUMBER, 0: shaders/) calls."""
        text = re.sub(r"//[^\n]*", "", path.read_text(encoding="utf-8"))
        called, own = {}, set(DEFINITION.findall(text))
        for function, (lab, file) in defined.items():
            if lab != number and function not in own and re.search(rf"\b{function}\s*\(", text):
                called.setdefault((lab, file), []).append(function)
        return [(number, path.name, lab, file, sorted(functions)) for (lab, file), functions in sorted(called.items())]

    rows = []
    for number, folder, files in stages:
        for name in files:
            path = ROOT / "solutions" / folder / name
            if path.is_file():
                rows += calls_in(path, number)
    # The framework's own passes (shaders/) that call a lab's function: number 0.
    for path in sorted((ROOT / "shaders").glob("*.*")):
        if path.suffix in (".frag", ".vert", ".glsl"):
            rows += calls_in(path, 0)
    return rows


def calls_markdown():
    lines = ["| lab | its solution's file | calls, of lab | that lab's file | functions | in stages |",
             "|---|---|---|---|---|---|"]
    last = stage_table()[-1][0]
    for number, name, lab, file, functions in calls_table():
        who = f"{number} | `{name}`" if number else f"framework | `shaders/{name}`"
        lines.append(f"| {who} | {lab} | `{file}` | {', '.join(f'`{f}`' for f in functions)} "
                     f"| {max(number, lab)}–{last} |")
    return "\n".join(lines)


def write_calls_doc():
    """Writes the calls table into instructor/changing_a_lab/README.md between its markers; True when it changed."""
    text = CALLS_DOC.read_text(encoding="utf-8")
    start, end = text.index(CALLS_BEGIN) + len(CALLS_BEGIN), text.index(CALLS_END)
    new = text[:start] + "\n" + calls_markdown() + "\n" + text[end:]
    if new != text:
        CALLS_DOC.write_text(new, encoding="utf-8")
    return new != text


def mark_entries(rows, field, reason):
    """Gives each row's catalogue entry FIELD = REASON (instructor/grading/catalogue.json, written
    only where one is), unless it has one; returns [(id, lab)] of the entries marked."""
    if not rows:
        return []
    path = ROOT / "instructor/grading/catalogue.json"
    catalogue = json.loads(path.read_text(encoding="utf-8"))
    ids = {r["id"] for r in rows}
    out = []
    for entry in catalogue["entries"]:
        if entry["id"] in ids and not entry.get(field):
            entry[field] = reason
            out.append((entry["id"], entry["lab"]))
    path.write_text(json.dumps(catalogue, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return out


def retire_stale(stale_rows, changed):
    """Marks each STALE row's entry "retired": its find text left the solution with the change."""
    labs = ",".join(map(str, changed))
    return mark_entries(stale_rows, "retired",
                        f"./kit rebaseline (labs {labs}): its find text is no longer in the solution; "
                        "rewrite its edits against the new solution and remove this, or delete the entry")


def gap_missed(missed_rows, changed):
    """Marks each MISSED mistake's entry with a "known_gap": no check shows it under the changed labs'
    solutions. The entry is still graded (GAP; OK with "caught now" where a later change shows it), and
    the report lists it to review: make it an equivalent, find a scene that shows it, or keep the gap
    with a reason of the course's own."""
    labs = ",".join(map(str, changed))
    return mark_entries(missed_rows, "known_gap",
                        f"./kit rebaseline (labs {labs}): keeps full marks under the changed solution; no check of "
                        "the lab shows it (review: an equivalent now, a scene that shows it, or this gap reworded)")


def hashes():
    out = {}
    for label, folder in WATCHED.items():
        for path in sorted(folder.glob("*")):
            if path.is_file():
                out[str(path.relative_to(ROOT))] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


STEP_STARTED = []  # (number, monotonic start) of each step begun, for the report's step times


def step(number, title):
    """Starts step NUMBER: says what it does and how long the one before took."""
    ended = time.monotonic()
    if STEP_STARTED:
        print(f"  (step {STEP_STARTED[-1][0]}: {ended - STEP_STARTED[-1][1]:.0f} s)", flush=True)
    STEP_STARTED.append((number, ended))
    print(f"\nrebaseline: step {number}/7: {title}", flush=True)


def run(cmd, **kwargs):
    """Runs a step's command, its output shown as it comes; returns its exit status."""
    print("  $ " + " ".join(str(c) for c in cmd), flush=True)
    return subprocess.run([str(c) for c in cmd], cwd=ROOT, **kwargs).returncode


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--labs", help="the labs changed, comma-separated (default: every lab)")
    parser.add_argument("--no-tests", action="store_true", help="leave out step 6, the quick tests")
    parser.add_argument("--calls-table", action="store_true", help="print the calls table and exit")
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build" / "default",
                        help="the build whose programs run (default: build/default)")
    args = parser.parse_args(argv)
    kit_grade = args.build.resolve() / "tools" / "kit-grade"
    if args.calls_table:
        print(calls_markdown())
        return 0
    numbers = [n for n, _, _ in stage_table()]
    changed = numbers
    if args.labs:
        try:
            first = min(int(x) for x in args.labs.split(","))
        except ValueError:
            parser.error(f"--labs takes lab numbers, comma-separated (got '{args.labs}')")
        if first not in numbers:
            parser.error(f"--labs: no lab {first} in the stage table ({', '.join(map(str, numbers))})")
        # A lab's solution is part of every later stage (stage_library): those changed with it.
        changed = [n for n in numbers if n >= first]
    started, problems = time.monotonic(), []
    env = dict(os.environ, KIT_ROOT=str(ROOT), KIT_SCENE_DIR=str(args.build.resolve() / "scenes"),
               KIT_BUILD_DIR=str(args.build.resolve()))
    before = hashes()

    step(1, "the labs' contracts (tools/grade/lab_contract.py sync, then shaders)")
    contract = subprocess.run([sys.executable, ROOT / "tools/grade/lab_contract.py", "sync"], cwd=ROOT,
                              capture_output=True, text=True)
    print(contract.stdout + contract.stderr, end="")
    contract_changes = [line.split("lab contract: ", 1)[1] for line in contract.stdout.splitlines() if "lab contract: " in line]
    shaders = subprocess.run([sys.executable, ROOT / "tools/grade/lab_contract.py", "shaders"], cwd=ROOT,
                             capture_output=True, text=True)
    print(shaders.stdout + shaders.stderr, end="")
    if contract.returncode != 0 or shaders.returncode != 0:
        problems.append("the labs' contracts: tools/grade/lab_contract.py failed (see above)")
        return report(before, None, [], problems, started)

    step(2, "references (kit-grade --update-references)")
    print(f"  $ {kit_grade} --update-references", flush=True)
    updated = subprocess.run([str(kit_grade), "--update-references"], cwd=ROOT, env=env, capture_output=True, text=True)
    print(updated.stdout + updated.stderr, end="")
    if updated.returncode != 0:
        problems.append("kit-grade --update-references failed: the solutions do not render (see above)")
        return report(before, None, [], problems, started)
    # A probed function the new solutions do not declare (tools/grade/frames/function_probes.h).
    probes_left_out = [line.split("says: ", 1)[1] for line in updated.stdout.splitlines()
                       if "function probe left out" in line and "says: " in line]

    # Every lab: the earlier ones' rows are the same as before, but the naming figures (step 3)
    # are measured over the whole catalogue, and a self-check of some labs leaves them stale.
    step(3, f"self-check with signatures, every lab (changed: {','.join(map(str, changed))})")
    rows_file = pathlib.Path(tempfile.mkstemp(prefix="kit-rebaseline-", suffix=".json")[1])
    signatures = ROOT / "tools/grade/references/mistakes.json"
    # With --write-signatures, the self-check grades again the caught mistakes of a lab whose
    # signatures changed, for the names kit-grade gives with the new ones (named_right).
    self_check = [sys.executable, ROOT / "instructor/grading/self_check.py", "--kit-grade", kit_grade, "--json", rows_file]
    print("  $ " + " ".join(str(c) for c in [*self_check, "--write-signatures", signatures]), flush=True)
    checked = subprocess.run([str(c) for c in [*self_check, "--write-signatures", signatures]], cwd=ROOT, env=env,
                             stdout=subprocess.PIPE, text=True)
    status = checked.returncode
    # Its table is in the rows; what it did with the signatures is worth a line here.
    print("".join(f"  {line}\n" for line in checked.stdout.splitlines() if line.startswith("self-check: ")), end="")
    try:
        rows = json.loads(rows_file.read_text())["rows"]
    except (OSError, ValueError, KeyError):
        rows = []
        problems.append(f"the self-check wrote no results (exit {status}): run ./kit grade --self-check to see why")
    # A STALE entry's find text left the solution with the change: retired in the catalogue
    # (self_check.py), named in the report, so that the suite passes and nothing is lost.
    retired = retire_stale([r for r in rows if r.get("verdict") == "STALE"], changed)
    # A MISSED mistake keeps full marks under the new solution: given a known gap, listed to review.
    gaps = gap_missed([r for r in rows if r.get("verdict") == "MISSED" and r.get("kind") == "mistake"], changed)
    rows = [r for r in rows if r.get("verdict") != "STALE" and (r["id"], r["lab"]) not in gaps]
    rows_needing = [r for r in rows if r.get("next_step")]
    if status != 0 and rows and not rows_needing and not retired and not gaps:
        problems.append(f"the self-check exited {status}: run ./kit grade --self-check to see why")
    if rows:
        failed = sum(r["verdict"] not in ("OK", "GAP") for r in rows)
        print(f"  {len(rows)} rows graded, {failed} failed")

    step(4, "handout figures (instructor/handout_figures.py --write)")
    figures = subprocess.run([sys.executable, ROOT / "instructor/handout_figures.py", "--write",
                              *(["--self-check-json", rows_file] if rows else [])],
                             cwd=ROOT, capture_output=True, text=True)
    print(figures.stdout, end="")
    if figures.returncode != 0:
        problems.append("handout figures: " + (figures.stdout + figures.stderr).strip())
    figure_changes = [line.split("written: ", 1)[1] for line in figures.stdout.splitlines() if "written: " in line]
    rows_file.unlink(missing_ok=True)

    step(5, "handout images (./kit handout-images)")
    if run([ROOT / "instructor/handout_images.sh"], env=env, stdout=subprocess.DEVNULL) != 0:
        problems.append("./kit handout-images failed (see above)")

    step(6, "the calls between labs (instructor/changing_a_lab/README.md)")
    calls_changed = write_calls_doc()
    print(f"  the calls table {'changed' if calls_changed else 'is unchanged'}")

    tests = "not run (--no-tests)"
    if not args.no_tests:
        step(7, "quick tests (./kit test --quick)")
        # Through ./kit, which builds what the quick tests load (the browser site among them);
        # another build's (--build) tests run in that build.
        if args.build.resolve() == (ROOT / "build" / "default").resolve():
            status = run([ROOT / "kit", "test", "--quick"], stdout=subprocess.DEVNULL)
        else:
            status = run(["ctest", "--test-dir", args.build, "--label-exclude", "slow", "-j", "2"],
                         stdout=subprocess.DEVNULL)
        tests = "passed" if status == 0 else "FAILED: run ./kit test --quick to see which"
        if status != 0:
            problems.append("the quick tests failed")
    return report(before, rows_needing, figure_changes, problems, started, tests, calls_changed, probes_left_out,
                  contract_changes, retired, gaps)


def report(before, rows_needing, figure_changes, problems, started, tests="not run", calls_changed=False,
           probes_left_out=(), contract_changes=(), retired=(), gaps=()):
    after = hashes()
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    if STEP_STARTED:
        print(f"  (step {STEP_STARTED[-1][0]}: {time.monotonic() - STEP_STARTED[-1][1]:.0f} s)", flush=True)
    print("\nrebaseline: report")
    for label, folder in WATCHED.items():
        prefix = str(folder.relative_to(ROOT)) + "/"
        mine = [p[len(prefix):] + ("" if p in after else " (removed)") + ("" if p in before else " (new)")
                for p in changed if p.startswith(prefix)]
        print(f"  {label} changed: {len(mine)}" + "".join(f"\n    {m}" for m in mine))
    print(f"  handout figures changed: {len(figure_changes)}" + "".join(f"\n    {f}" for f in figure_changes))
    if contract_changes:
        print(f"  the labs' contracts changed (tools/grade/lab_functions.json, the probe shaders written again): "
              f"{len(contract_changes)}" + "".join(f"\n    {c}" for c in contract_changes))
    if calls_changed:
        print("  the calls table in instructor/changing_a_lab/README.md changed: a lab calls other functions now")
    if probes_left_out:
        print(f"  function probes left out: {len(probes_left_out)} (the solutions do not declare the function)"
              + "".join(f"\n    {p}" for p in probes_left_out)
              + "\n      next step: declare the function in the lab's starter as the solution does (the "
                "contract follows the starters), or leave it unprobed")
    if retired:
        print(f"  catalogue entries retired (their find text left the solution; instructor/grading/catalogue.json): "
              f"{len(retired)}" + "".join(f"\n    {i} (lab {lab})" for i, lab in retired)
              + "\n      next step: rewrite each against the new solution and remove its \"retired\", or delete it")
    if gaps:
        print(f"  catalogue entries given a known_gap (they keep full marks now; instructor/grading/catalogue.json): "
              f"{len(gaps)}" + "".join(f"\n    {i} (lab {lab})" for i, lab in gaps)
              + "\n      next step: review each: an equivalent now, a scene that shows it, or the gap in your words")
    if rows_needing is not None:
        print(f"  catalogue entries that need a decision: {len(rows_needing)}")
        for r in rows_needing:
            score = f"{r['score']:g}/{r['max_score']:g}" if r.get("score") is not None else "-"
            print(f"    {r['verdict']}: {r['id']} (lab {r['lab']}, {r['kind']}, {score})\n      next step: {r['next_step']}")
    print(f"  quick tests: {tests}")
    for p in problems:
        print(f"  problem: {p}")
    print(f"rebaseline: {time.monotonic() - started:.0f} s; "
          + ("nothing needs a decision" if not problems and not rows_needing else "see above")
          + ("; commit the changed files with the change that made them" if changed or figure_changes or contract_changes or retired or gaps else
             "; no file changed"))
    return 1 if problems or rows_needing else 0


if __name__ == "__main__":
    sys.exit(main())
