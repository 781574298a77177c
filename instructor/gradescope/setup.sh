#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (the zip is unpacked into /autograder/source). Three steps:
#   1. install the packages and build only what grading needs (./kit setup
#      --grading: kit-render, kit-scenes, kit-grade; no viewer, no tests), so the
#      package list lives in one place (the kit script);
#   2. grade the reference solutions with the shipped references: the tolerances
#      are measured across OpenGL implementations (handouts/instructors.md,
#      Portable verdicts), so on Gradescope's Mesa they get full marks and the
#      shipped references stay: a student's own check (./kit grade labs) then
#      agrees with the official grade. Only where they do not (an implementation
#      outside the measured ones, or references older than the solutions) are the
#      references rendered again on this image, and it says so;
#   3. the reference solutions must then score full marks: an autograder that
#      cannot give them full marks fails here, in the image build the instructor
#      sees, and not on every student's submission.
#
# Environment (for testing it outside Gradescope; instructor/tests/gradescope_test.sh):
#   KIT_GRADE_BIN  a kit-grade already built: skips step 1
set -euo pipefail

SOURCE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
KIT="$SOURCE/kit"
say() { printf 'setup.sh: %s\n' "$*" >&2; }

[ -x "$KIT/kit" ] || { say "no kit in $KIT: was the zip made by ./kit gradescope-package?"; exit 1; }

KIT_LABS=  # empty: every lab (kit-grade's default); autograder.conf names them
# shellcheck source=/dev/null
[ -f "$SOURCE/autograder.conf" ] && . "$SOURCE/autograder.conf"

start=$SECONDS
if [ -n "${KIT_GRADE_BIN:-}" ]; then
  GRADER="$KIT_GRADE_BIN"
else
  if ! command -v apt-get >/dev/null; then
    say "this image has no apt-get: choose a Debian or Ubuntu base image (README: instructor/gradescope/README.md)"
    exit 1
  fi
  # Installs what is missing (apt-get) and builds build/default. If a package is
  # not in this image's apt sources, apt-get names it: pick another base image.
  "$KIT/kit" setup --grading
  GRADER="$KIT/build/default/tools/kit-grade"
  say "kit built in $((SECONDS - start)) s"
fi
[ -x "$GRADER" ] || { say "no kit-grade at $GRADER"; exit 1; }
export KIT_ROOT="$KIT"

# full_marks DIR: grades the reference solutions into DIR; true when every lab gets full marks
# (the labs that do not are printed).
full_marks() {
  "$GRADER" "$KIT/solutions" ${KIT_LABS:+--labs "$KIT_LABS"} --out "$1" >/dev/null
  python3 - "$1/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
bad = {lab: v for lab, v in s["labs"].items() if v["status"] != "graded" or v["score"] < v["max_score"] - 1e-9}
for lab, v in sorted(bad.items()):
    print(f"setup.sh: lab {lab}: the reference solution scored {v['score']}/{v['max_score']} ({v['status']})", file=sys.stderr)
sys.exit(1 if bad else 0)
PY
}

check="$(mktemp -d)"
trap 'rm -rf "$check"' EXIT
# Step 2: the shipped references, unless the solutions lose points with them here.
if full_marks "$check/shipped"; then
  say "the reference solutions get full marks with the shipped references on this image: they are kept"
else
  say "the reference solutions lose points with the shipped references on this image (renderer: $(python3 -c \
'import json,sys; print(json.load(open(sys.argv[1]))["renderer"])' "$check/shipped/summary.json")): rendering them again here"
  "$GRADER" --update-references >&2  # prints the GL renderer it used
  # Step 3: the reference solutions must score full marks on this image.
  if ! full_marks "$check/rendered"; then
    say "the reference solutions do not get full marks on this image: see below; not ready"
    cat "$check/rendered/results.json" >&2 || true
    exit 1
  fi
fi
say "ready: labs ${KIT_LABS:-(every lab)}; the reference solutions get full marks ($((SECONDS - start)) s in all)"
