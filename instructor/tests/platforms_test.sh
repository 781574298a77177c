#!/usr/bin/env bash
# One submission, three platforms, the same verdict: labs/ with lab 1's solution less its
# emission output (it passes some checks and fails others), lab 2's starter and lab 3's
# solution is graded through Gradescope's run_autograder (labs 1,2,3 at once), the PrairieLearn entrypoint
# (one question per lab) and the Classroom 50 autograder.py (one bundle per lab). Every
# check must pass or fail alike and score alike on all three, and each lab's share of its
# points must agree.
#
# usage: instructor/tests/platforms_test.sh PATH/TO/kit-grade
# shellcheck source=support/platform_test.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/platform_test.sh"
LABS=(1 2 3)

SUB="$TMP/submission"
mkdir -p "$SUB/labs"
cp -r "$ROOT/solutions/01-gbuffer" "$ROOT/labs/02-lighting" "$ROOT/solutions/03-attenuation" "$SUB/labs/"
sed -i 's|out_emission = vec4(emissive, 0.0);|out_emission = vec4(0.0);|' "$SUB/labs/01-gbuffer/gbuffer.frag"
grep -q 'out_emission = vec4(0.0);' "$SUB/labs/01-gbuffer/gbuffer.frag" || { echo "FAIL: lab 1's emission line moved"; exit 1; }

# Gradescope: the zip unpacked into a temporary /autograder.
"$ROOT/instructor/gradescope/package.sh" --out "$TMP/ag.zip" >/dev/null 2>&1
AG="$TMP/autograder"
mkdir -p "$AG/source" "$AG/results"
unzip -q "$TMP/ag.zip" -d "$AG/source"
cp -r "$SUB" "$AG/submission"
(cd "$AG" && AUTOGRADER_ROOT="$AG" KIT_ROOT="$AG/source/kit" KIT_GRADE_BIN="$GRADER" KIT_LABS=1,2,3 \
   source/run_autograder) >"$TMP/gradescope.log" 2>&1 || { tail "$TMP/gradescope.log"; exit 1; }

# PrairieLearn: one question per lab, the lab's files uploaded loose.
KIT_GRADE_BIN="$GRADER" "$ROOT/instructor/prairielearn/package.sh" "$TMP/pl" --labs 1,2,3 >/dev/null 2>"$TMP/pl.log" ||
  { cat "$TMP/pl.log"; exit 1; }
# Classroom 50: one bundle per lab, the submission's folder as the checkout.
KIT_GRADE_BIN="$GRADER" "$ROOT/instructor/classroom50/package.sh" "$TMP/c50" --labs 1,2,3 >/dev/null 2>"$TMP/c50.log" || { cat "$TMP/c50.log"; exit 1; }
export CLASSROOM=c ASSIGNMENT=a SUBMISSION_TAG=submit/t COMMIT_URL=https://x/c RELEASE_URL=https://x/r REVIEW_URL=https://x/v
for n in "${LABS[@]}"; do
  q="$(cd "$TMP/pl/questions/deferred-kit" && ls -d "lab0$n-"*)"
  g="$TMP/grade-$n"
  mkdir -p "$g/student" "$g/tests"
  cp "$SUB/labs/${q#lab}"/* "$g/student/"
  cp "$TMP/pl/questions/deferred-kit/$q/tests/lab.json" "$g/tests/"
  GRADE_ROOT="$g" KIT_GRADE_BIN="$GRADER" "$TMP/pl/serverFilesCourse/deferred-kit/entrypoint.py" 2>>"$TMP/pl.log"
  (cd "$SUB" && KIT_GRADE_BIN="$GRADER" python3 "$TMP/c50/autograders/$q/autograder.py") 2>>"$TMP/c50.log"
  mv "$SUB/result.json" "$TMP/c50-$n.json"
  rm -f "$SUB/kit-grade-report.html"
done

"$PY" - "$TMP" "$ROOT/tools/grade/grading.json" "${LABS[@]}" <<'PY'
import json, sys
tmp, config, *labs = sys.argv[1:]
gs = json.load(open(f"{tmp}/autograder/results/results.json"))
gradescope = {t["name"]: (t["status"] == "passed", round(t["score"], 3)) for t in gs["tests"]}
pl, c50, shares = {}, {}, {}
# What each platform tells a student about a failed check: kit-grade's guess at the mistake.
guesses = {"Gradescope": {t["name"]: t.get("output", "") for t in gs["tests"] if t["status"] != "passed"}}
guesses["PrairieLearn"], guesses["Classroom 50"] = {}, {}
for n in labs:
    r = json.load(open(f"{tmp}/grade-{n}/results/results.json"))
    pl.update({t["name"]: (t["points"] >= t["max_points"] > 0, round(t["points"], 3)) for t in r["tests"]})
    guesses["PrairieLearn"].update({t["name"]: t.get("output", "") for t in r["tests"] if t["points"] < t["max_points"]})
    c = json.load(open(f"{tmp}/c50-{n}.json"))
    c50.update({t["test-name"]: (t["passed"], round(t["kit-grade"]["score"], 3)) for t in c["tests"]})
    guesses["Classroom 50"].update({t["test-name"]: t["kit-grade"].get("likely", "") for t in c["tests"] if not t["passed"]})
    shares[n] = (r["score"], c["score"] / c["max-score"])
errors = []
for platform, texts in guesses.items():
    for name, text in texts.items():
        if name.startswith("lab 1") and "Looks like: " not in text:
            errors.append(f"{platform}: {name} fails without naming a likely mistake: {text[:200]!r}")
if not (set(gradescope) == set(pl) == set(c50)):
    errors.append(f"the platforms name different checks: {sorted(set(gradescope) ^ set(pl))} {sorted(set(gradescope) ^ set(c50))}")
for name in sorted(set(gradescope) & set(pl) & set(c50)):
    if not (gradescope[name] == pl[name] == c50[name]):
        errors.append(f"{name}: Gradescope {gradescope[name]}, PrairieLearn {pl[name]}, Classroom 50 {c50[name]}")
for n, (a, b) in shares.items():
    if abs(a - b) > 1e-3:
        errors.append(f"lab {n}: PrairieLearn {a:.4f} of the points, Classroom 50 {b:.4f}")
passed = sum(v[0] for v in gradescope.values())
if not 0 < passed < len(gradescope):
    errors.append(f"the submission should pass some checks and fail others ({passed} of {len(gradescope)} passed)")
if errors:
    print("FAIL: " + "\nFAIL: ".join(errors))
    sys.exit(1)
print(f"ok: {len(gradescope)} checks of labs {', '.join(labs)}: the same pass/fail and score on Gradescope, "
      f"PrairieLearn and Classroom 50 ({passed} passed); shares " +
      ", ".join(f"lab {n} {a:.3f}" for n, (a, b) in shares.items()))
PY
finish
