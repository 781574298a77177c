#!/usr/bin/env bash
# The Classroom 50 autograder, end to end, without GitHub: ./kit classroom50-package writes
# lab 2's bundle; a clean clone of the student copy for lab 2 is the working directory, the
# runner's environment variables are set, and autograder.py runs with this build's kit-grade
# (KIT_GRADE_BIN: the build on the runner is what instructor/classroom50/README.md times).
# Checked: result.json's schema (classroom50/result/v1, integer scores, one test per check
# with kit-grade's numbers), the starter scores under half and the solution full marks, a
# checkout whose tools/, references and grading.json were edited or removed grades the same,
# a low score exits 0 and a broken set-up does not.
#
# usage: instructor/tests/classroom50_test.sh PATH/TO/kit-grade
# shellcheck source=support/platform_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/platform_test.sh"

KIT_GRADE_BIN="$GRADER" "$ROOT/instructor/classroom50/package.sh" "$TMP/c50" --labs 2 >/dev/null 2>"$TMP/package.log" || { cat "$TMP/package.log"; exit 1; }
BUNDLE="$TMP/c50/autograders/lab02-lighting"
[ -x "$BUNDLE/autograder.py" ] && [ -f "$BUNDLE/platform_results.py" ] && [ -f "$BUNDLE/kit/tools/grade/grading.json" ] ||
  fail "the bundle lacks autograder.py, platform_results.py or kit/"
[ ! -e "$BUNDLE/kit/labs" ] || fail "the bundle carries labs/ (the student's)"
[ ! -e "$BUNDLE/kit/solutions/02-lighting" ] || fail "the bundle carries lab 2's solution"
[ ! -e "$BUNDLE/kit/instructor" ] || fail "the bundle carries instructor/"
if "$PY" - "$TMP/c50/runtime.json" "$("$ROOT/kit" packages --grading | tr '\n' ' ')" <<'PY'
import json, sys
rt = json.load(open(sys.argv[1]))
sys.exit(0 if rt.get("runs-on") == "ubuntu-latest" and rt.get("apt") == sys.argv[2].split() else 1)
PY
then pass "package: lab 2's bundle (no labs/, no solution of lab 2), runtime.json from ./kit packages --grading"
else fail "runtime.json is not ubuntu-latest with ./kit packages --grading"; fi

# A student's repository: the student copy for lab 2, cloned clean.
python3 "$ROOT/instructor/student_copy/student_copy.py" 2 "$TMP/template" >/dev/null 2>&1
git clone -q "$TMP/template" "$TMP/repo"
export CLASSROOM=graphics ASSIGNMENT=lab2-lighting SUBMISSION_TAG=submit/2026-01-01T00-00-00Z-abc1234
export COMMIT_URL=https://github.com/org/repo/commit/abc1234 RELEASE_URL=https://github.com/org/repo/releases/tag/submit%2Fx
export REVIEW_URL=https://github.com/org/repo/compare/base...abc1234

# check NAME EXPECT(full|low|zero) [SCORE]: autograder.py in $TMP/repo; SCORE: the score it must give.
check() {
  local name="$1" expect="$2" want="${3:-}" summary
  rm -f "$TMP/repo/result.json" "$TMP/repo/kit-grade-report.html"
  if ! (cd "$TMP/repo" && KIT_GRADE_BIN="$GRADER" python3 "$BUNDLE/autograder.py") >"$TMP/run.log" 2>&1; then
    fail "$name: autograder.py exited non-zero"; tail -5 "$TMP/run.log" | sed 's/^/    /'; return
  fi
  if summary="$("$PY" - "$TMP/repo/result.json" "$expect" "$want" "$ROOT/tools/grade/grading.json" <<'PY' 2>&1
import json, os, re, sys
path, expect, want, config = sys.argv[1:]
r = json.load(open(path))
keys = {"schema", "classroom", "assignment", "submission", "commit", "release", "review", "datetime", "score", "max-score", "tests"}
errors = [f"missing {k}" for k in keys - set(r)]
if r.get("schema") != "classroom50/result/v1": errors.append(f"schema {r.get('schema')!r}")
for k, env in (("classroom", "CLASSROOM"), ("assignment", "ASSIGNMENT"), ("submission", "SUBMISSION_TAG"),
               ("commit", "COMMIT_URL"), ("release", "RELEASE_URL"), ("review", "REVIEW_URL")):
    if r.get(k) != os.environ[env]: errors.append(f"{k} is {r.get(k)!r}, not ${env}")
if not re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", r.get("datetime", "")): errors.append(f"datetime {r.get('datetime')!r}")
tests = r.get("tests", [])
for t in tests:
    if not (isinstance(t.get("test-name"), str) and isinstance(t.get("passed"), bool)): errors.append(f"test {t}: name/passed")
    if not all(type(t.get(k)) is int for k in ("score", "max-score")): errors.append(f"{t.get('test-name')}: scores not integers")
    if not isinstance(t.get("kit-grade", {}).get("max_score"), (int, float)): errors.append(f"{t.get('test-name')}: no kit-grade numbers")
checks = json.load(open(config))["labs"]["2"]["checks"]
if len(tests) != len(checks): errors.append(f"{len(tests)} tests for {len(checks)} checks")
if type(r.get("score")) is not int or type(r.get("max-score")) is not int: errors.append("score or max-score not an integer")
if r.get("score") != sum(t["score"] for t in tests) or r.get("max-score") != sum(t["max-score"] for t in tests):
    errors.append("score / max-score are not the tests' sums")
ok = {"full": r["score"] == r["max-score"] > 0, "low": r["score"] < r["max-score"] / 2, "zero": r["score"] == 0}[expect]
if not ok: errors.append(f"expected {expect}, got {r['score']}/{r['max-score']}")
if want and str(r["score"]) != want: errors.append(f"score {r['score']}, expected {want}")
if errors: sys.exit("; ".join(errors))
print(f"{r['score']}/{r['max-score']} over {len(tests)} tests")
PY
)"; then
    [ -s "$TMP/repo/kit-grade-report.html" ] && ! grep -q 'src="img/' "$TMP/repo/kit-grade-report.html" ||
      { fail "$name: no self-contained kit-grade-report.html"; return; }
    pass "$name: $summary"
  else
    fail "$name: $summary"
  fi
}

check "starter (the clean clone)" low
starter_score="$("$PY" -c 'import json; print(json.load(open("'"$TMP/repo/result.json"'"))["score"])')"

# The student edits what grades in their own checkout: it changes nothing.
"$PY" - "$TMP/repo/tools/grade/grading.json" <<'PY'
import json, sys
p = sys.argv[1]; c = json.load(open(p))
for t in c["tolerances"].values():
    for k in t:
        if isinstance(t[k], (int, float)): t[k] = 1e9 if k != "min_changed_percent" else 0
json.dump(c, open(p, "w"))
PY
for f in "$TMP/repo/tools/grade/references"/lab2-*; do cp "$TMP/repo/tools/grade/references/lab1-default-albedo.png" "$f" 2>/dev/null || true; done
rm -rf "$TMP/repo/shaders" "$TMP/repo/solutions"
# Witness: graded with the checkout's grading.json, the tampering would pay.
if KIT_ROOT="$BUNDLE/kit" "$GRADER" "$TMP/repo/labs" --labs 2 --config "$TMP/repo/tools/grade/grading.json" \
     --references "$ROOT/tools/grade/references" --out "$TMP/witness" >/dev/null 2>&1 &&
   "$PY" -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))["labs"]["2"]["score"] > 0 else 1)' "$TMP/witness/summary.json"; then
  pass "witness: the checkout's tampered grading.json would give the starter points"
else
  fail "witness: the tampered grading.json gives the starter nothing even when used"
fi
check "starter, the checkout's grading.json, references, shaders/ and solutions/ tampered with" low "$starter_score"

cp "$ROOT/solutions/02-lighting"/* "$TMP/repo/labs/02-lighting/"
check "solution" full

rm -rf "$TMP/repo/labs"
check "no labs/ at all (a low score, not a broken set-up)" zero

if (cd "$TMP/repo" && KIT_GRADE_BIN="$TMP/no-such-kit-grade" python3 "$BUNDLE/autograder.py") >"$TMP/broken.log" 2>&1; then
  fail "a broken set-up (no kit-grade) exited 0"
else
  pass "a broken set-up (no kit-grade) exits non-zero: $(grep -m1 '::error::' "$TMP/broken.log" || true)"
fi

finish
