#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image
# (the zip is unpacked into /autograder/source). It installs the Debian/Ubuntu
# packages and builds the kit through ./kit setup, so the package list lives in
# one place (the kit script), then grades the reference solutions once: an
# autograder that cannot give them full marks fails here, in the image build the
# instructor sees, and not on every student's submission.
set -euo pipefail

SOURCE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
KIT="$SOURCE/kit"
say() { printf 'setup.sh: %s\n' "$*" >&2; }

[ -x "$KIT/kit" ] || { say "no kit in $KIT: was the zip made by ./kit gradescope-package?"; exit 1; }
if ! command -v apt-get >/dev/null; then
  say "this image has no apt-get: choose a Debian or Ubuntu base image (README: instructor/gradescope/README.md)"
  exit 1
fi

KIT_LABS=1,2,3,4,5
# shellcheck source=/dev/null
[ -f "$SOURCE/autograder.conf" ] && . "$SOURCE/autograder.conf"

start=$SECONDS
# Installs what is missing (apt-get) and builds build/default. If a package is
# not in this image's apt sources, apt-get names it: pick a newer base image.
"$KIT/kit" setup
GRADER="$KIT/build/default/tools/kit-grade"
[ -x "$GRADER" ] || { say "the build did not produce $GRADER"; exit 1; }
say "kit built in $((SECONDS - start)) s"

# Smoke test: the reference solutions must score full marks on this image.
check="$(mktemp -d)"
trap 'rm -rf "$check"' EXIT
"$GRADER" "$KIT/solutions" --labs "$KIT_LABS" --out "$check"
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
say "ready: labs $KIT_LABS; the reference solutions get full marks ($((SECONDS - start)) s in all)"
