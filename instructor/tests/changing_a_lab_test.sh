#!/usr/bin/env bash
# The worked example of instructor/changing_a_lab/README.md, end to end: lab 2's geometric
# term replaced by Smith's with Schlick-GGX (smith_schlick_ggx.patch: the solution, the
# starter, the handout's formula and the CPU reference: four files by hand; lab 6's table
# calls lab 2's microfacet_geometry, whose signature stays), then the one command,
# ./kit rebaseline, on a copy of this kit with this build's programs.
#   1. the patch applies to the kit as it is, and was made against its files as they are (its
#      index lines: a course's changed file is taken back to them); a change to the files it
#      edits that breaks either fails here: make the patch again against the new files;
#   2. witness: before the rebaseline, the new solution loses points against the old references;
#   3. rebaseline --labs 2 --no-tests exits 0: references and signatures made again, the
#      self-check of labs 2-7 passes, nothing needs a decision; the mistake the new term hides
#      (lighting-position-from-depth) is given a known gap, listed to review;
#   4. then the new solutions of labs 2 and 6 get full marks, and the kit's own lab 2 (the
#      min(1, ...) term) loses points.
# Run: changing_a_lab_test.sh BUILD_DIR WORK_DIR
set -uo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$(cd "$1" && pwd)"
WORK="$2"
GRADE="$BUILD/tools/kit-grade"
failures=0 passed=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; passed=$((passed + 1)); }

rm -rf "$WORK" && mkdir -p "$WORK/kit"
# The kit as it is now (tracked and new files, not the build), as an instructor's checkout holds it.
(cd "$ROOT" && git ls-files -co --exclude-standard -z | xargs -0 cp --parents -t "$WORK/kit") ||
  { echo "FAIL: cannot copy the kit"; exit 1; }
rm -rf "$WORK/kit/build"
COPY="$WORK/kit"

PATCH="$ROOT/instructor/changing_a_lab/smith_schlick_ggx.patch"
# patch_bases: "FILE BASE" for each file the patch edits, BASE the blob its index line names
# (the file's text the patch was made against).
patch_bases() {
  awk '/^diff --git/ { file = substr($4, 3) } /^index / { split($2, h, "\\.\\."); print file, h[1] }' "$PATCH"
}
# as_shipped DIR: where the patch does not apply to a file of DIR, that file as the kit shipped
# it, the text the patch was made against (its "index BASE..NEW" line names the blob, which
# the kit's git history holds), so that the example runs on the kit's lab, whatever a course
# changed since (this very example adopted, say). Prints what it restored; returns 1 where a
# blob is not in the history (a copy of the kit without it).
as_shipped() {
  local file base missing=0
  git -C "$1" apply --check "$PATCH" 2>"$WORK/apply.log" && return 0
  for file in $(sed -n 's/^error: patch failed: \(.*\):[0-9]*$/\1/p' "$WORK/apply.log" | sort -u); do
    base="$(patch_bases | awk -v f="$file" '$1 == f { print $2; exit }')"
    if [ -n "$base" ] && git -C "$ROOT" cat-file blob "$base" >"$1/$file.shipped" 2>/dev/null; then
      mv "$1/$file.shipped" "$1/$file"
      echo "$file"
    else
      rm -f "$1/$file.shipped"
      echo "$file (not in this repository's history)"
      missing=1
    fi
  done
  return "$missing"
}

# The copy is a repository of its own: git apply run inside another repository's tree (the
# build folder lies in the kit's) applies a patch relative to that one's root, and leaves
# out, without a word, every path outside the folder it runs in.
git init -q "$COPY"

# Witness of as_shipped: the files as shipped (from the history), then a lab 2 solution a
# course has changed where the patch edits it.
mkdir -p "$WORK/course" && git init -q "$WORK/course"
patch_bases | while read -r file base; do
  mkdir -p "$WORK/course/$(dirname "$file")"
  git -C "$ROOT" cat-file blob "$base" >"$WORK/course/$file" 2>/dev/null || cp "$COPY/$file" "$WORK/course/$file"
done
sed -i 's/return min(1.0, min(2.0 \* n_dot_h/return min(0.999, min(2.0 * n_dot_h/' \
  "$WORK/course/solutions/02-lighting/brdf.glsl"
if ! git -C "$WORK/course" apply --check "$PATCH" 2>/dev/null &&
   [ "$(as_shipped "$WORK/course")" = "solutions/02-lighting/brdf.glsl" ] && git -C "$WORK/course" apply --check "$PATCH"; then
  ok "witness: a course's changed lab 2 is taken back to the lab as shipped, and the patch applies"
else
  fail "witness: a course's changed lab 2 solution was not taken back to the lab as shipped"
fi

restored="$(as_shipped "$COPY")"
status=$?
if [ -n "$restored" ]; then
  echo "ok: this course has changed what the worked example edits; the example runs on the kit's lab as shipped:"
  echo "$restored" | sed 's/^/    /'
fi
if [ "$status" -ne 0 ]; then
  echo "ok: the kit's files as shipped are not in this repository's history: the worked example is not run here"
  echo "$((passed + 1)) passed, $failures failed"
  [ "$failures" -eq 0 ]
  exit
fi
# The kit's lab 2 as shipped, the min(1, ...) term, kept to grade after the rebaseline.
mkdir -p "$WORK/old" && cp -r "$COPY/solutions/02-lighting" "$WORK/old/"
old_lab2="$WORK/old"
# The patch's base (its index lines) must be the kit's files as they are, not an older version
# it still applies to: a course's changed file is taken back to that base (as_shipped above).
if [ -z "$restored" ]; then
  stale="$(patch_bases | while read -r file base; do
    [ "$(git hash-object "$COPY/$file" | cut -c1-${#base})" = "$base" ] || echo "$file"
  done)"
  [ -z "$stale" ] && ok "the patch was made against the kit's files as they are" ||
    fail "the patch's base is an older version of $(echo $stale): make it again (apply it, then git diff)"
fi
# The four files the README names, and no other: lab 6 follows lab 2's function unedited.
edited="$(patch_bases | cut -d' ' -f1 | sort | tr '\n' ' ')"
[ "$edited" = "handouts/02-lighting.md instructor/reference/cpu_reference.cpp labs/02-lighting/brdf.glsl solutions/02-lighting/brdf.glsl " ] &&
  ok "the patch edits the four files by hand: $edited" || fail "the patch edits $edited, not the four files the README names"
if git -C "$COPY" apply "$PATCH" && grep -q "(roughness + 1.0) \* (roughness + 1.0) / 8.0" "$COPY/solutions/02-lighting/brdf.glsl"; then
  ok "the patch applies"
else
  echo "FAIL: instructor/changing_a_lab/smith_schlick_ggx.patch no longer applies: make it again against the kit's files"
  exit 1
fi

# score SUBMISSION LAB: the lab's score/max from kit-grade run on the copy.
score() {
  local out="$WORK/grade-$RANDOM"
  KIT_ROOT="$COPY" KIT_SCENE_DIR="$BUILD/scenes" "$GRADE" "$1" --labs "$2" --out "$out" --jobs 2 >"$out.log" 2>&1
  python3 -c 'import json,sys; l=json.load(open(sys.argv[1]))["labs"][sys.argv[2]]; print("%g/%g" % (l["score"], l["max_score"]))' \
    "$out/summary.json" "$2" 2>/dev/null || echo "no-summary(see $out.log)"
}
submission() {  # submission NAME FOLDER: a submission holding FOLDER (a lab folder) as it is
  mkdir -p "$WORK/$1" && cp -r "$2" "$WORK/$1/" && echo "$WORK/$1"
}
new_lab2="$(submission new "$COPY/solutions/02-lighting")"

before="$(score "$new_lab2" 2)"
if [ -n "$restored" ]; then
  # The course's references are its own lab's already: the example changes nothing they hold.
  ok "the new solution scores $before before the rebaseline (this course's references, not the kit's as shipped)"
else
  [ "$before" != "10/10" ] && [ "${before#no-summary}" = "$before" ] && ok "witness: before the rebaseline the new solution scores $before" ||
    fail "witness: the new solution scored $before against the old references: the patch changes nothing the grader sees"
fi

start=$SECONDS
if python3 "$COPY/instructor/changing_a_lab/rebaseline.py" --labs 2 --no-tests --build "$BUILD" >"$WORK/rebaseline.log" 2>&1; then
  ok "rebaseline --labs 2 exited 0 ($((SECONDS - start)) s): $(tail -n 1 "$WORK/rebaseline.log")"
else
  fail "rebaseline --labs 2 exited non-zero; its report:"
  sed -n '/rebaseline: report/,$p' "$WORK/rebaseline.log"
fi
grep -q "catalogue entries that need a decision: 0" "$WORK/rebaseline.log" && ok "no catalogue entry needs a decision" ||
  fail "the report names catalogue entries to decide on"
gap="$(python3 -c 'import json, sys
entries = json.load(open(sys.argv[1]))["entries"]
print(next((e.get("known_gap", "") for e in entries if e["id"] == "lighting-position-from-depth"), ""))' \
  "$COPY/instructor/grading/catalogue.json")"
# A course that adopted the change has its own gap there already (its rebaseline gave it): kept.
[ -n "$gap" ] && { grep -q "lighting-position-from-depth (lab 2)" "$WORK/rebaseline.log" || [ -n "$restored" ]; } &&
  ok "the mistake Smith's G hides is given a known gap and listed to review: ${gap:0:60}..." ||
  fail "lighting-position-from-depth has no known gap, or the report does not list it"
if [ -n "$restored" ]; then
  ok "the report lists $(sed -n 's/^  references changed: //p' "$WORK/rebaseline.log") changed references (this course's are its own lab's already)"
else
  grep -q "references changed: [1-9]" "$WORK/rebaseline.log" && ok "the report lists the changed references" ||
    fail "the report names no changed reference"
fi

after="$(score "$new_lab2" 2)"
[ "$after" = "10/10" ] && ok "after it the new lab 2 solution scores 10/10" || fail "the new lab 2 solution scores $after"
lab6="$(score "$COPY/solutions" 6)"
[ "$lab6" = "10/10" ] && ok "and lab 6's solution, unedited (its BRDF table calls lab 2's microfacet_geometry), 10/10" ||
  fail "the new lab 6 solution scores $lab6"
old="$(score "$old_lab2" 2)"
[ "$old" != "10/10" ] && [ "${old#no-summary}" = "$old" ] && ok "the kit's own lab 2, min(1, ...), scores $old" ||
  fail "the old lab 2 solution scores $old: it should lose points"

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
