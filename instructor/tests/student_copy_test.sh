#!/usr/bin/env bash
# ./kit student-copy, tried as a new student would use the copy (built without OSMesa, as
# Mesa 25.1 and later are: step 3).
# usage: student_copy_test.sh PATH/TO/kit-grade WORK_DIR
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
WORK="${2:?usage: student_copy_test.sh PATH/TO/kit-grade WORK_DIR}"
PY=/usr/bin/python3
rm -rf "$WORK" && mkdir -p "$WORK"
failures=0
fail() { printf 'FAIL: %s\n' "$*"; failures=$((failures + 1)); }
pass() { printf 'ok: %s\n' "$*"; }
score() {  # summary.json lab -> "score/max status"
  "$PY" - "$1" "$2" <<'PY'
import json, sys
lab = json.load(open(sys.argv[1]))["labs"][sys.argv[2]]
print("%g/%g %s" % (lab["score"], lab["max_score"], lab["status"]))
PY
}

# 1. A copy for every lab of the stage table (its labs/NN-name folders): written, no
#    solution line of that lab or later in it, every Markdown link resolving inside it
#    and no student document naming instructor/ or an instructor command
#    (student_copy.py runs leak_check.py and doc_check.py and fails on a finding).
LABS=$(ls "$ROOT/labs" | sed -n 's/^0*\([0-9][0-9]*\)-.*/\1/p')
for n in $LABS; do
  if "$ROOT/kit" student-copy "$n" "$WORK/copy$n" >"$WORK/copy$n.log" 2>&1; then
    pass "copy for lab $n: $(tail -2 "$WORK/copy$n.log" | head -1)"
  else
    fail "copy for lab $n"; sed 's/^/    /' "$WORK/copy$n.log" | tail -10
  fi
done
for n in $LABS; do
  [ -d "$WORK/copy$n/instructor" ] && fail "copy $n holds instructor/"
  for doc in handouts/instructors.md handouts/README.md; do
    [ -e "$WORK/copy$n/$doc" ] && fail "copy $n holds the instructors' $doc"
  done
  grep -rl --include='*.md' -e "<!-- /\?instructors -->" "$WORK/copy$n" && fail "copy $n kept an instructors' marker"
  ls -d "$WORK/copy$n"/labs/"$(printf '%02d' "$n")"-* >/dev/null 2>&1 || fail "copy $n lacks the starters of lab $n"
  for d in "$WORK/copy$n"/solutions/*/; do
    [ -d "$d" ] || continue
    m=$((10#$(basename "$d" | cut -d- -f1)))
    [ "$m" -ge "$n" ] && fail "copy $n holds $(basename "$d")"
  done
done
[ -f "$WORK/copy2/tools/grade/references/manifest.json" ] || fail "copy 2 has no grader references"
# The dev container comes with every copy (its ctest, tests/devcontainer, runs in step 3's ./kit test).
for n in $LABS; do
  for f in .devcontainer/devcontainer.json .devcontainer/Dockerfile .devcontainer/install.sh; do
    [ -f "$WORK/copy$n/$f" ] || fail "copy $n lacks $f"
    git -C "$WORK/copy$n" ls-files --error-unmatch "$f" >/dev/null 2>&1 || fail "copy $n's repository does not track $f"
  done
done
grep -q "for \*\*lab 2\*\*" "$WORK/copy2/README.md" || fail "copy 2's README is not the students' one"

# 2. Witnesses: the leak check finds a solution line planted in a handout, and a
#    released-too-early solution folder.
cp -r "$WORK/copy2" "$WORK/planted"
grep -m1 'return f0 + (1.0 - f0)' "$ROOT/solutions/02-lighting/brdf.glsl" >>"$WORK/planted/handouts/02-lighting.md"
if "$PY" "$ROOT/instructor/student_copy/leak_check.py" "$WORK/planted" 2 >"$WORK/planted.log" 2>&1; then
  fail "witness: a lab-2 solution line planted in a handout was not found"
else
  grep -q "handouts/02-lighting.md" "$WORK/planted.log" && pass "witness: planted solution line found ($(head -1 "$WORK/planted.log"))" \
    || fail "witness: the leak report does not name the handout"
fi
rm -rf "$WORK/planted" && cp -r "$WORK/copy2" "$WORK/planted" && cp -r "$ROOT/solutions/03-attenuation" "$WORK/planted/solutions/"
"$PY" "$ROOT/instructor/student_copy/leak_check.py" "$WORK/planted" 2 >"$WORK/planted.log" 2>&1 \
  && fail "witness: solutions/03-attenuation in a copy for lab 2 was not reported" \
  || pass "witness: an unreleased solution folder is reported"
rm -rf "$WORK/planted"
# doc_check.py: a dead image link and an instructor command planted in a handout, and
# an instructor path in a shader comment, are each reported by file.
cp -r "$WORK/copy2" "$WORK/planted"
printf '\n![chart](../instructor/bench/results/ibl_speed_accuracy.png)\n\nRun `./kit bench --ibl-only`.\n' \
  >>"$WORK/planted/handouts/06-ibl.md"
printf '// see instructor/reference/ibl_reference.h\n' >>"$WORK/planted/shaders/environment.glsl"
if "$PY" "$ROOT/instructor/student_copy/doc_check.py" "$WORK/planted" >"$WORK/planted.log" 2>&1; then
  fail "witness: a dead link and instructor names planted in the copy were not reported"
else
  for expected in "handouts/06-ibl.md:.*is not in the copy" "handouts/06-ibl.md:.*instructor command" \
                  "shaders/environment.glsl:.*instructor/ folder"; do
    grep -q "$expected" "$WORK/planted.log" && pass "witness: doc_check reports '$expected'" \
      || fail "witness: doc_check does not report '$expected': $(head -3 "$WORK/planted.log")"
  done
fi
rm -rf "$WORK/planted"

# 3. The copy for lab 2 from a fresh clone: the README's two commands. It is built as on a
# distribution whose Mesa (25.1 and later) has no OSMesa (KIT_CMAKE_ARGS=-DKIT_OSMESA=OFF
# builds as if libosmesa6-dev were missing), so that this one second build of the kit
# proves both the copy and the kit without OSMesa: the demo, the copy's tests and its
# grades below all run on EGL.
# A student's machine has caches of its own: the copy's Mesa shader cache and grader
# seed are kept apart from the instructor's (which the kit's other tests write meanwhile).
# Compiled objects are the exception: the copy's build takes from the compiler cache every
# object that compiles as the kit's did (CMakeLists.txt, ccache), its own cache folder kept.
if command -v ccache >/dev/null 2>&1; then
  CCACHE_DIR="${CCACHE_DIR:-$(ccache -k cache_dir)}"
  export CCACHE_DIR
fi
export XDG_CACHE_HOME="$WORK/cache"
git clone -q "$WORK/copy2" "$WORK/clone"
cd "$WORK/clone"
if KIT_CMAKE_ARGS=-DKIT_OSMESA=OFF ./kit demo >"$WORK/demo.log" 2>&1; then
  ls out/demo/02-lighting-your-lab.png >/dev/null 2>&1 && ls out/demo/01-gbuffer-albedo.png >/dev/null 2>&1 \
    && pass "copy: ./kit demo (solution of lab 1, the student's lab 2)" || fail "copy: ./kit demo wrote $(ls out/demo)"
else
  fail "copy: ./kit demo"; tail -20 "$WORK/demo.log" | sed 's/^/    /'
fi
if ./kit test >"$WORK/test.log" 2>&1; then
  pass "copy: ./kit test ($(grep -E 'tests passed' "$WORK/test.log"))"
else
  fail "copy: ./kit test"; tail -30 "$WORK/test.log" | sed 's/^/    /'
fi
[ -e build/default/tools/kit-bench ] && fail "copy: kit-bench was built in a student copy"

# 3b. Without OSMesa: nothing links it, EGL is the default, --backend osmesa is refused by
# name, and EGL writes the very bytes the instructor's build writes with its default
# backend (OSMesa where it has it; test_backends compares the two within one build).
render=build/default/tools/kit-render
grep -q "^KIT_OSMESA:BOOL=OFF" build/default/CMakeCache.txt && pass "copy: configured with KIT_OSMESA=OFF" \
  || fail "copy: KIT_CMAKE_ARGS=-DKIT_OSMESA=OFF did not reach the configure"
if ldd "$render" | grep -qi osmesa; then fail "copy: kit-render links OSMesa"; else pass "copy: no OSMesa linked"; fi
args=(--solution --stage gbuffer --view albedo --size 160x120)
out="$("$render" "${args[@]}" --out "$WORK/egl.png" --timings 2>&1)" || fail "copy: kit-render failed: $out"
grep -q "(egl: " <<<"$out" && pass "copy: EGL is the default backend" || fail "copy: the default backend is not EGL: $out"
if out="$("$render" "${args[@]}" --backend osmesa --out "$WORK/osmesa.png" 2>&1)"; then
  fail "copy: --backend osmesa was accepted"
else
  grep -q "this build of the kit has no OSMesa" <<<"$out" && pass "copy: --backend osmesa refused by name" \
    || fail "copy: --backend osmesa: unclear refusal: $out"
fi
"$(dirname "$1")/kit-render" "${args[@]}" --out "$WORK/kit.png" >/dev/null 2>&1 || fail "the kit's kit-render failed"
cmp -s "$WORK/egl.png" "$WORK/kit.png" && pass "copy (EGL) and kit render the same bytes" \
  || fail "copy (EGL) and the kit's render differ"

# 4. The copy's grader: the starter scores low, the solution full, as in the kit.
./kit grade labs --labs 2 --out "$WORK/starter" >"$WORK/grade-starter.log" 2>&1 || fail "copy: grading the starter failed"
s="$(score "$WORK/starter/summary.json" 2)"
case "$s" in 0/*|[0-3]/*|[0-3].*) pass "copy: the starter of lab 2 scores $s" ;; *) fail "copy: the starter of lab 2 scores $s" ;; esac
mkdir -p "$WORK/solution-submission/labs" && cp -r "$ROOT/solutions/02-lighting" "$WORK/solution-submission/labs/"
./kit grade "$WORK/solution-submission" --labs 2 --out "$WORK/solution" >"$WORK/grade-solution.log" 2>&1 || fail "copy: grading the solution failed"
s="$(score "$WORK/solution/summary.json" 2)"
[ "$s" = "10/10 graded" ] && pass "copy: the solution of lab 2 scores $s" || fail "copy: the solution of lab 2 scores $s"
# The same grade from the instructor's grader, the same report.
"$1" "$WORK/solution-submission" --labs 2 --out "$WORK/solution-kit" >/dev/null 2>&1 || true
[ "$(score "$WORK/solution-kit/summary.json" 2)" = "$s" ] && pass "copy and kit grade the solution alike" \
  || fail "copy and kit disagree: $(score "$WORK/solution-kit/summary.json" 2) vs $s"
./kit grade labs --labs 3 >"$WORK/grade-lab3.log" 2>&1 && fail "copy: lab 3 graded without lab 2's solution" \
  || { grep -q "solutions/02-lighting" "$WORK/grade-lab3.log" && pass "copy: lab 3 refused, naming the missing solution" \
       || fail "copy: lab 3 refused without naming the solution: $(tail -1 "$WORK/grade-lab3.log")"; }
./kit bench --quick >"$WORK/bench.log" 2>&1 && fail "copy: ./kit bench ran" \
  || { grep -q "instructor command" "$WORK/bench.log" && pass "copy: ./kit bench says it is an instructor command" || fail "copy: ./kit bench: $(cat "$WORK/bench.log")"; }

if [ "$failures" -gt 0 ]; then
  echo "student_copy: $failures check(s) failed"
  exit 1
fi
echo "student_copy: every check passed"
