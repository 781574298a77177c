#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (the zip is unpacked into /autograder/source). Three steps:
#   1. install the packages and build only what grading needs (./kit setup
#      --grading: kit-render, kit-scenes, kit-grade; no viewer, no tests), so the
#      package list lives in one place (the kit script);
#   2. render the references again from the shipped solutions, on this image:
#      the Mesa of Gradescope's Ubuntu image may round differently from the one
#      the shipped references were made with, and a reference from another Mesa
#      would cost every student the same points. The comparison with the shipped
#      references is printed first, so the instructor sees whether it mattered;
#   3. grade the reference solutions: an autograder that cannot give them full
#      marks fails here, in the image build the instructor sees, and not on every
#      student's submission.
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

# Step 2: the references, rendered on this image.
if "$GRADER" --check-references >"$SOURCE/references-check.log" 2>&1; then
  say "the shipped references match this image's renders of the solutions"
else
  say "this image renders the solutions differently from the shipped references:"
  sed 's/^/  /' "$SOURCE/references-check.log" | head -20 >&2
fi
"$GRADER" --update-references >&2  # prints the GL renderer it used

# Step 3: the reference solutions must score full marks on this image.
check="$(mktemp -d)"
trap 'rm -rf "$check"' EXIT
"$GRADER" "$KIT/solutions" ${KIT_LABS:+--labs "$KIT_LABS"} --out "$check"
if ! python3 - "$check/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
bad = {lab: v for lab, v in s["labs"].items() if v["status"] != "graded" or v["score"] < v["max_score"] - 1e-9}
for lab, v in sorted(bad.items()):
    print(f"setup.sh: lab {lab}: the reference solution scored {v['score']}/{v['max_score']} ({v['status']})", file=sys.stderr)
sys.exit(1 if bad else 0)
PY
then
  say "the reference solutions do not get full marks on this image: see $check/results.json above; not ready"
  cat "$check/results.json" >&2 || true
  exit 1
fi
say "ready: labs ${KIT_LABS:-(every lab)}; the reference solutions get full marks ($((SECONDS - start)) s in all)"
