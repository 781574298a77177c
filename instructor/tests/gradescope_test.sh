#!/usr/bin/env bash
# The Gradescope autograder, end to end, without Gradescope and without network:
# ./kit gradescope-package's zip is unpacked into a temporary /autograder layout
# (source/, submission/, results/) and run_autograder grades with the kit-grade
# this build made (KIT_GRADE_BIN), reading the kit's data from the unpacked zip
# (KIT_ROOT), so a file missing from the package fails here. Every results.json
# is checked against Gradescope's schema.
#
# usage: instructor/tests/gradescope_test.sh PATH/TO/kit-grade
# shellcheck source=support/platform_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/platform_test.sh"

# --- the package ---------------------------------------------------------
"$ROOT/instructor/gradescope/package.sh" --out "$TMP/autograder.zip" >/dev/null 2>"$TMP/package.log" || { cat "$TMP/package.log"; exit 1; }
AG="$TMP/autograder"
mkdir -p "$AG/source"
unzip -q "$TMP/autograder.zip" -d "$AG/source"
listing="$(unzip -Z1 "$TMP/autograder.zip")"
for f in setup.sh run_autograder autograder.conf kit/kit kit/CMakeLists.txt kit/tools/grade/grading.json \
         kit/solutions/01-gbuffer/gbuffer.frag kit/solutions/05-postprocess/blur.frag kit/shaders/guards.glsl; do
  grep -qx "$f" <<<"$listing" || fail "the zip has no $f"
done
for f in setup.sh run_autograder kit/kit; do
  [ -x "$AG/source/$f" ] || fail "$f is not executable once unpacked"
done
if grep -qE '^kit/(build|out|\.git)/' <<<"$listing"; then fail "the zip holds build output or .git"; fi
pass "package: $(wc -l <<<"$listing") entries, setup.sh and run_autograder at the root"
# Gradescope copies run_autograder to /autograder/run_autograder and runs it from there.
cp "$AG/source/run_autograder" "$AG/run_autograder"

# Checks results.json against Gradescope's schema; "full" also wants every point.
validate() {  # results.json expect(full|zero|partial) [text the output must contain]
  "$PY" - "$@" <<'PY'
import json, math, sys

path, expect = sys.argv[1], sys.argv[2]
needle = sys.argv[3] if len(sys.argv) > 3 else None
VIS = {"hidden", "after_due_date", "after_published", "visible"}
FORMATS = {"text", "html", "simple_format", "md", "ansi"}
TOP = {"score", "execution_time", "output", "output_format", "test_output_format", "test_name_format",
       "visibility", "stdout_visibility", "extra_data", "tests", "leaderboard"}
TEST = {"score", "max_score", "status", "name", "name_format", "number", "output", "output_format",
        "tags", "visibility", "extra_data"}
errors = []

def number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)

try:
    r = json.load(open(path))
except (OSError, ValueError) as e:
    sys.exit(f"{path}: not readable JSON: {e}")
if not isinstance(r, dict):
    sys.exit(f"{path}: the top level is not an object")
errors += [f"unknown top-level key '{k}'" for k in r if k not in TOP]
if not number(r.get("score")):
    errors.append("'score' missing or not a finite number")
if "execution_time" in r and not number(r["execution_time"]):
    errors.append("'execution_time' is not a number")
for key in ("visibility", "stdout_visibility"):
    if key in r and r[key] not in VIS:
        errors.append(f"'{key}' is {r[key]!r}, not one of {sorted(VIS)}")
for key in ("output_format", "test_output_format"):
    if key in r and r[key] not in FORMATS:
        errors.append(f"'{key}' is {r[key]!r}")
if "output" in r and not isinstance(r["output"], str):
    errors.append("'output' is not a string")
tests = r.get("tests")
if not isinstance(tests, list) or not tests:
    errors.append("'tests' missing or empty")
    tests = []
for i, t in enumerate(tests):
    where = f"tests[{i}]"
    if not isinstance(t, dict):
        errors.append(f"{where} is not an object")
        continue
    where += f" ({t.get('name')!r})"
    errors += [f"{where}: unknown key '{k}'" for k in t if k not in TEST]
    if not isinstance(t.get("name"), str) or not t["name"]:
        errors.append(f"{where}: 'name' missing")
    for key in ("score", "max_score"):
        if not number(t.get(key)):
            errors.append(f"{where}: '{key}' missing or not a number")
    if "status" in t and t["status"] not in ("passed", "failed"):
        errors.append(f"{where}: 'status' is {t['status']!r}")
    if "output" in t and not isinstance(t["output"], str):
        errors.append(f"{where}: 'output' is not a string")
    if "output_format" in t and t["output_format"] not in FORMATS:
        errors.append(f"{where}: 'output_format' is {t['output_format']!r}")
    if "visibility" in t and t["visibility"] not in VIS:
        errors.append(f"{where}: 'visibility' is {t['visibility']!r}")
    if "tags" in t and not (isinstance(t["tags"], list) and all(isinstance(x, str) for x in t["tags"])):
        errors.append(f"{where}: 'tags' is not a list of strings")
lb = r.get("leaderboard", [])
if not isinstance(lb, list):
    errors.append("'leaderboard' is not a list")
else:
    for i, e in enumerate(lb):
        if not (isinstance(e, dict) and isinstance(e.get("name"), str) and "value" in e):
            errors.append(f"leaderboard[{i}] needs 'name' and 'value'")
        elif "order" in e and e["order"] not in ("asc", "desc"):
            errors.append(f"leaderboard[{i}]: 'order' is {e['order']!r}")
if errors:
    sys.exit(f"{path}: not Gradescope's schema:\n  " + "\n  ".join(errors))

score = r["score"]
possible = sum(t["max_score"] for t in tests)
if expect == "full":
    short = [f"{t['name']}: {t['score']}/{t['max_score']}" for t in tests if t["score"] < t["max_score"] - 1e-9]
    # Per-test points are printed rounded (1.667 for 10/6), so their sum may miss the total by the rounding.
    if short or possible <= 0 or abs(score - possible) > 0.0005 * len(tests) + 1e-9:
        sys.exit(f"{path}: expected full marks, got {score}/{possible}:\n  " + "\n  ".join(short))
elif expect == "zero" and score != 0:
    sys.exit(f"{path}: expected a score of 0, got {score}")
if needle:
    text = r.get("output", "") + "".join(t.get("output", "") for t in tests)
    if needle.lower() not in text.lower():
        sys.exit(f"{path}: no output mentions {needle!r}")
print(f"{score:g}/{possible:g} over {len(tests)} tests")
PY
}

# One simulated Gradescope run: $1 names it, $2 the expectation, $3 the text the
# output must contain (optional); the submission is whatever $AG/submission holds.
run_case() {
  local name="$1" expect="$2" needle="${3:-}" log="$TMP/$1.log" summary
  rm -rf "$AG/results"
  mkdir -p "$AG/results"
  if ! (cd "$AG" && env AUTOGRADER_ROOT="$AG" KIT_ROOT="$AG/source/kit" "${RUN_ENV[@]}" ./run_autograder) >"$log" 2>&1; then
    fail "$name: run_autograder exited non-zero (log below)"; tail -n 20 "$log" | sed 's/^/    /'; return
  fi
  if [ ! -f "$AG/results/results.json" ]; then
    fail "$name: no results/results.json (log below)"; tail -n 20 "$log" | sed 's/^/    /'; return
  fi
  local args=("$AG/results/results.json" "$expect")
  [ -n "$needle" ] && args+=("$needle")
  if summary="$(validate "${args[@]}" 2>&1)"; then
    pass "$name: $summary"
  else
    fail "$name: $summary"; tail -n 20 "$log" | sed 's/^/    /'
  fi
}

new_submission() { rm -rf "$AG/submission"; mkdir -p "$AG/submission"; }

# 1. The reference solutions of every lab in a student's kit repository (a GitHub
#    submission): labs/ is graded, the repository's own solutions/ is not.
new_submission
mkdir -p "$AG/submission/labs" "$AG/submission/solutions"
cp -r "$ROOT"/solutions/[0-9][0-9]-* "$AG/submission/labs/"
cp -r "$ROOT"/labs/[0-9][0-9]-* "$AG/submission/solutions/"
cp "$ROOT/kit" "$AG/submission/kit"
RUN_ENV=(KIT_GRADE_BIN="$GRADER")
run_case "solutions, every lab, in a kit repository" full

# 2. A one-lab assignment (KIT_LABS=2) with the files dragged in on their own.
new_submission
cp "$ROOT"/solutions/02-lighting/* "$AG/submission/"
RUN_ENV=(KIT_GRADE_BIN="$GRADER" KIT_LABS=2)
run_case "lab 2 alone, files uploaded without their folder" full

# 3. The same as a .zip of the lab folder.
new_submission
(cd "$ROOT/solutions" && zip -q -r "$AG/submission/lab3.zip" 03-attenuation)
RUN_ENV=(KIT_GRADE_BIN="$GRADER" KIT_LABS=3)
run_case "lab 3 as a zip" full

# 4. Nothing submitted: graded, scores nothing, still a valid results.json.
new_submission
RUN_ENV=(KIT_GRADE_BIN="$GRADER" KIT_LABS=1)
run_case "empty submission" zero

# 5. The build failed (no kit-grade): a valid results.json that says so.
new_submission
cp -r "$ROOT"/solutions/01-gbuffer "$AG/submission/"
RUN_ENV=(KIT_GRADE_BIN="$TMP/no-such-kit-grade")
run_case "autograder not built" zero "not built"

# 6. setup.sh on an image where the solutions lose points with the shipped references
#    (simulated: one reference brightened by 8/255, as references older than the solutions
#    or an implementation outside the measured ones would). Witness first: graded against
#    that reference, the solution of lab 2 loses points. Then setup.sh says so, renders the
#    references again on this image and proves full marks. First, with the references as
#    shipped, it keeps them.
REFS="$AG/source/kit/tools/grade/references"
if (cd "$AG/source" && env KIT_GRADE_BIN="$GRADER" ./setup.sh) >"$TMP/setup-kept.log" 2>&1 &&
   grep -q "with the shipped references on this image: they are kept" "$TMP/setup-kept.log"; then
  pass "setup.sh: the solutions get full marks with the shipped references, which are kept"
else
  fail "setup.sh did not keep the shipped references (log below)"; sed 's/^/    /' "$TMP/setup-kept.log" | tail -20
fi
oiiotool "$REFS/lab2-default-final.png" --addc 0.03 -o "$REFS/lab2-default-final.png"
witness="$(env KIT_ROOT="$AG/source/kit" "$GRADER" "$ROOT/solutions/02-lighting" --labs 2 --out "$TMP/witness" 2>&1)" || true
if "$PY" -c 'import json,sys; s=json.load(open(sys.argv[1]))["labs"]["2"]; sys.exit(0 if s["score"] < s["max_score"] else 1)' \
     "$TMP/witness/summary.json" 2>/dev/null; then
  pass "witness: a reference from another renderer costs the solution of lab 2 points"
else
  fail "witness: the brightened reference did not cost the solution of lab 2 anything"; echo "$witness" | tail -5
fi
if (cd "$AG/source" && env KIT_GRADE_BIN="$GRADER" ./setup.sh) >"$TMP/setup.log" 2>&1; then
  if grep -q "lose points with the shipped references" "$TMP/setup.log" && grep -q "ready: labs" "$TMP/setup.log"; then
    pass "setup.sh: saw the stale reference, rendered the references on this image, full marks"
  else
    fail "setup.sh passed without reporting the stale reference (log below)"; sed 's/^/    /' "$TMP/setup.log" | tail -20
  fi
else
  fail "setup.sh failed (log below)"; sed 's/^/    /' "$TMP/setup.log" | tail -20
fi

finish
