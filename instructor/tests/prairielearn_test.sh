#!/usr/bin/env bash
# The PrairieLearn external grader, end to end, without PrairieLearn or Docker:
# ./kit prairielearn-package writes the course files (it grades every lab's solution
# through the entrypoint on its way), then each case lays out a temporary /grade
# (student/, tests/lab.json from the question) and runs the entrypoint from
# serverFilesCourse with this build's kit-grade (KIT_GRADE_BIN). Every results.json is
# checked: valid JSON, under 1 MB, PrairieLearn's fields, images for every failed check.
#
# usage: instructor/tests/prairielearn_test.sh PATH/TO/kit-grade
# shellcheck source=support/platform_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/platform_test.sh"

# --- the package -----------------------------------------------------------------------
PL="$TMP/course"
if ! KIT_GRADE_BIN="$GRADER" "$ROOT/instructor/prairielearn/package.sh" "$PL" >/dev/null 2>"$TMP/package.log"; then
  cat "$TMP/package.log"; exit 1
fi
ENTRY="$PL/serverFilesCourse/deferred-kit/entrypoint.py"
mapfile -t QUESTIONS < <(cd "$PL/questions/deferred-kit" && ls)
[ ${#QUESTIONS[@]} -eq "$(ls -d "$ROOT"/solutions/[0-9][0-9]-*/ | wc -l)" ] || fail "not one question per lab: ${QUESTIONS[*]}"
"$PY" - "$PL" "${QUESTIONS[@]}" <<'PY' && pass "package: ${#QUESTIONS[@]} questions, info.json and question.html as PrairieLearn reads them" || fail "package: see above"
import json, re, sys
from pathlib import Path
pl, questions = Path(sys.argv[1]), sys.argv[2:]
errors = []
for q in questions:
    d = pl / "questions" / "deferred-kit" / q
    info = json.loads((d / "info.json").read_text())
    lab = json.loads((d / "tests" / "lab.json").read_text())
    for key in ("uuid", "type", "title", "topic"):
        if key not in info: errors.append(f"{q}: info.json has no {key}")
    if info.get("gradingMethod") != "External": errors.append(f"{q}: gradingMethod is not External")
    ego = info.get("externalGradingOptions", {})
    if not (ego.get("enabled") is True and ego.get("image") and ego.get("entrypoint", "").startswith("/grade/serverFilesCourse/")):
        errors.append(f"{q}: externalGradingOptions incomplete: {ego}")
    if not (isinstance(ego.get("timeout"), int) and 0 < ego["timeout"] <= 600): errors.append(f"{q}: timeout {ego.get('timeout')}")
    if not re.search(r"in \d+(\.\d+)? s \(wall", ego.get("comment", "")): errors.append(f"{q}: no measured time beside the timeout")
    if lab["wall_limit"] >= ego["timeout"]: errors.append(f"{q}: kit-grade's wall limit is not under the timeout")
    html = (d / "question.html").read_text()
    m = re.search(r'<pl-file-upload file-names="([^"]*)"', html)
    if not m or [f.strip() for f in m.group(1).split(",")] != lab["files"]: errors.append(f"{q}: pl-file-upload does not name {lab['files']}")
    if "<pl-external-grader-results>" not in html: errors.append(f"{q}: no pl-external-grader-results")
    if (pl / "image" / "kit" / "solutions").exists(): errors.append("the image's build context holds solutions/")
print("\n".join(errors)) if errors else None
sys.exit(1 if errors else 0)
PY
grep -q 'kit packages --grading' "$PL/image/Dockerfile" || fail "the Dockerfile does not install from ./kit packages --grading"

# validate results.json expect(full|low|zero|ungradable) [text the results must mention]
validate() {
  "$PY" - "$@" <<'PY'
import json, math, sys
from pathlib import Path
path, expect = Path(sys.argv[1]), sys.argv[2]
needle = sys.argv[3] if len(sys.argv) > 3 else None
size = path.stat().st_size
if size >= 1_000_000: sys.exit(f"{size} bytes: over PrairieLearn's 1 MB")
r = json.loads(path.read_text())
errors = []
gradable = r.get("gradable", True)
if not gradable:
    fe = r.get("format_errors")
    if not (isinstance(fe, str) or (isinstance(fe, list) and fe and all(isinstance(x, str) for x in fe))):
        errors.append("gradable false without format_errors")
else:
    s = r.get("score")
    if not (isinstance(s, (int, float)) and math.isfinite(s) and 0 <= s <= 1): errors.append(f"score {s!r} not in [0, 1]")
    for t in r.get("tests", []):
        for k in ("name", "points", "max_points", "message", "output"):
            if k not in t: errors.append(f"test {t.get('name')!r} has no {k}")
        failed = t.get("points", 0) < t.get("max_points", 0)
        graded = "Not graded" not in t.get("message", "")
        if failed and graded and not t.get("images"): errors.append(f"failed test {t['name']!r} has no images")
        for im in t.get("images", []):
            if not (isinstance(im, dict) and im.get("url", "").startswith("data:image/png;base64,") and im.get("label")):
                errors.append(f"test {t['name']!r}: image is not a labelled data: URL")
    if not r.get("tests"): errors.append("no tests")
want = {"full": lambda: gradable and r["score"] == 1.0, "low": lambda: gradable and r["score"] < 0.5,
        "zero": lambda: gradable and r["score"] == 0, "ungradable": lambda: not gradable}[expect]
if not want(): errors.append(f"expected {expect}: gradable {gradable}, score {r.get('score')}")
if needle and needle.lower() not in json.dumps(r).lower(): errors.append(f"nothing mentions {needle!r}")
if errors: sys.exit("; ".join(errors))
images = sum(len(t.get("images", [])) for t in r.get("tests", []))
print(f"score {r.get('score')}, gradable {gradable}, {size} bytes, {images} images")
PY
}

# run_case NAME QUESTION EXPECT [NEEDLE]: grades $TMP/student as QUESTION's submission.
run_case() {
  local name="$1" question="$2" expect="$3" needle="${4:-}" g="$TMP/grade/$1" summary
  rm -rf "$g" && mkdir -p "$g/tests" "$g/data"
  cp -r "$TMP/student" "$g/student"
  cp "$PL/questions/deferred-kit/$question/tests/lab.json" "$g/tests/"
  echo '{}' >"$g/data/data.json"
  local t0=$SECONDS
  if ! env GRADE_ROOT="$g" KIT_GRADE_BIN="$GRADER" "${RUN_ENV[@]}" "$ENTRY" >"$g.log" 2>&1; then
    fail "$name: the entrypoint exited non-zero"; tail -5 "$g.log" | sed 's/^/    /'; return
  fi
  ELAPSED=$((SECONDS - t0))
  [ -f "$g/results/results.json" ] || { fail "$name: no results/results.json"; tail -5 "$g.log" | sed 's/^/    /'; return; }
  local args=("$g/results/results.json" "$expect")
  [ -n "$needle" ] && args+=("$needle")
  if summary="$(validate "${args[@]}" 2>&1)"; then pass "$name: $summary"; else fail "$name: $summary"; fi
}
new_student() { rm -rf "$TMP/student"; mkdir -p "$TMP/student"; }
RUN_ENV=()

# 1. Every lab's solution and starter, uploaded as pl-file-upload leaves them (loose files).
for q in "${QUESTIONS[@]}"; do
  folder="$(printf '%s' "${q#lab}")"  # NN-name
  new_student; cp "$ROOT/solutions/$folder"/* "$TMP/student/"
  run_case "$q solution" "$q" full
  if [ -d "$ROOT/labs/$folder" ]; then
    new_student; cp "$ROOT/labs/$folder"/* "$TMP/student/"
    run_case "$q starter" "$q" low
  fi
done

# 2. A file missing: not gradable, and the message names it.
new_student; cp "$ROOT/solutions/02-lighting/brdf.glsl" "$TMP/student/"
run_case "lab 2 without lighting.frag" lab02-lighting ungradable "lighting.frag"

# 3. A shader that does not compile: gradable, 0, the compiler's message with file and line.
new_student; cp "$ROOT/solutions/02-lighting"/* "$TMP/student/"
"$PY" - "$TMP/student/lighting.frag" <<'PY'
import sys
p = sys.argv[1]; lines = open(p).read().split("\n")
lines.insert(11, "this is not GLSL;")  # becomes line 12
open(p, "w").write("\n".join(lines))
PY
run_case "lab 2 compile error" lab02-lighting zero "lighting.frag:12"

# 4. An endless loop (the compiler cannot remove it: it depends on a uniform): a timed-out
#    message within the question's timeout. A small CPU limit keeps the test short; one
#    llvmpipe thread spins on one core only.
new_student; cp "$ROOT/solutions/02-lighting"/* "$TMP/student/"
"$PY" - "$TMP/student/lighting.frag" <<'PY'
import sys
p = sys.argv[1]; s = open(p).read()
s = s.replace("void main() {\n", "void main() {\n    float x = 1.0;\n    while (x > 0.0) x += u_resolution.x;  // never ends\n"
              "    if (x < 0.0) discard;\n", 1)
open(p, "w").write(s)
PY
RUN_ENV=(KIT_CPU_LIMIT=3 KIT_TIMEOUT=15 LP_NUM_THREADS=1)
run_case "lab 2 endless loop" lab02-lighting zero "timed out"
timeout="$("$PY" -c 'import json,sys; print(json.load(open(sys.argv[1]))["externalGradingOptions"]["timeout"])' \
  "$PL/questions/deferred-kit/lab02-lighting/info.json")"
if [ "${ELAPSED:-999}" -lt "$timeout" ]; then pass "the endless loop was reported in ${ELAPSED} s, within the question's $timeout s"
else fail "the endless loop took ${ELAPSED:-?} s, the question's timeout is $timeout s"; fi
RUN_ENV=()

# 5. The 1 MB limit: the same failing renders under a tenth of the budget keep the file
#    under it and say which images were left out.
"$PY" - "$ROOT/instructor/platforms" "$GRADER" "$ROOT" "$TMP" <<'PY' && pass "a small budget: images left out and named, still under it" || fail "the budget was not kept"
import json, os, subprocess, sys
sys.path.insert(0, sys.argv[1])
import platform_results as p
grader, root, tmp = sys.argv[2:]
out = f"{tmp}/budget"
subprocess.run([grader, f"{root}/labs", "--labs", "1", "--out", out], check=True, capture_output=True)
r = p.prairielearn(out, 1, f"{root}/tools/grade/grading.json", limit=100_000)
size = len(json.dumps(r).encode())
assert size < 100_000, size
assert "left out" in r["output"], r["output"][-300:]
assert any(t.get("images") for t in r["tests"]), "no image at all fitted"
PY

finish
