#!/usr/bin/env bash
# ./kit classroom50-package DIR [--labs 1,2]
#
# Writes, per lab, what a Classroom 50 assignment grading that lab needs
# (instructor/classroom50/README.md):
#   DIR/autograders/labNN-name/   the bundle: copy it to CLASSROOM/autograders/ASSIGNMENT/ in
#                                 the classroom50 repository. autograder.py, platform_results.py,
#                                 bundle.json (the lab) and kit/: the student copy for lab NN
#                                 (./kit student-copy, so its leak check applies: no solution of
#                                 lab NN or later) less labs/. autograder.py builds kit-grade from
#                                 kit/ on the runner and grades the student's labs/ against kit/'s
#                                 references and grading.json, never the checkout's.
#   DIR/runtime.json              the assignment's runtime block (gh teacher assignment add
#                                 --runtime runtime.json): ubuntu-latest and the kit's grading
#                                 packages, from the kit's one list (./kit packages --grading)
# release_assets: ["kit-grade-report.html"] (the report autograder.py writes).
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
LABS=""
DEST=""

say() { printf 'classroom50-package: %s\n' "$*" >&2; }
die() { say "$*"; exit 1; }
usage() {
  cat <<'USAGE'
usage: ./kit classroom50-package DIR [--labs LIST]
  DIR           where to write the bundles (must not exist, or be empty)
  --labs LIST   labs to write a bundle for, comma separated (default: every lab)
USAGE
}
while [ $# -gt 0 ]; do
  case "$1" in
    --labs) [ $# -ge 2 ] || die "--labs needs a value"; LABS="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    -*) usage >&2; die "unknown option '$1'" ;;
    *) [ -z "$DEST" ] || die "one DIR only"; DEST="$1"; shift ;;
  esac
done
[ -n "$DEST" ] || { usage >&2; die "DIR is missing"; }
case "$DEST" in /*) ;; *) DEST="$PWD/$DEST" ;; esac
if [ -e "$DEST" ] && [ -n "$(ls -A "$DEST" 2>/dev/null)" ]; then die "$DEST exists and is not empty"; fi

FOLDERS_TEXT="$(python3 "$ROOT/instructor/platforms/platform_results.py" folders --kit "$ROOT" --labs "$LABS")" || die "no bundle written"
mapfile -t FOLDERS <<<"$FOLDERS_TEXT"

GRADER="${KIT_GRADE_BIN:-$ROOT/build/default/tools/kit-grade}"
[ -x "$GRADER" ] || die "no kit-grade at $GRADER (./kit setup builds it)"
mkdir -p "$DEST/autograders"
ok=0
CHECK="$(mktemp -d)"
trap 'rm -rf "$CHECK"; [ "$ok" = 1 ] || { say "failed: nothing written"; rm -rf "$DEST"; }' EXIT
left_out=()

for folder in "${FOLDERS[@]}"; do
  n=$((10#${folder%%-*}))
  b="$DEST/autograders/lab$(printf '%02d' "$n")-${folder#*-}"
  python3 "$ROOT/instructor/student_copy/student_copy.py" "$n" "$b/kit" --no-git >/dev/null 2>"$DEST/student-copy.log" ||
    { cat "$DEST/student-copy.log" >&2; die "lab $n: student-copy failed"; }
  # labs/ is the student's: the bundle grades the checkout's, so it carries none of its own.
  rm -rf "$b/kit/labs"
  install -m 0755 "$HERE/autograder.py" "$b/autograder.py"
  install -m 0644 "$ROOT/instructor/platforms/platform_results.py" "$b/platform_results.py"
  printf '{\n  "lab": %d,\n  "folder": "%s"\n}\n' "$n" "$folder" >"$b/bundle.json"
  for needed in kit/kit kit/tools/grade/grading.json kit/tools/grade/lab_functions.json kit/tools/grade/references kit/shaders; do
    [ -e "$b/$needed" ] || die "lab $n: the bundle has no $needed"
  done
  # The bundle must give the lab's solution full marks with nothing but its own kit/: a
  # lab whose checks needed that lab's own solution at grading time could not be graded
  # from a bundle students can read, and would be left out rather than graded wrong.
  rm -rf "$CHECK/repo" && mkdir -p "$CHECK/repo/labs" && cp -r "$ROOT/solutions/$folder" "$CHECK/repo/labs/"
  start=$(date +%s.%N)
  (cd "$CHECK/repo" && CLASSROOM=check ASSIGNMENT=check SUBMISSION_TAG=check COMMIT_URL=check RELEASE_URL=check \
     KIT_GRADE_BIN="$GRADER" python3 "$b/autograder.py") >"$CHECK/log" 2>&1 || { cat "$CHECK/log" >&2; die "lab $n: autograder.py failed on the solution"; }
  secs="$(python3 -c "print(f'{$(date +%s.%N) - $start:.1f}')")"
  verdict="$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(r["score"], r["max-score"], next((t["kit-grade"].get("message", "") for t in r["tests"] if not t["passed"]), ""))' "$CHECK/repo/result.json")"
  read -r got max why <<<"$verdict"
  if [ "$got" != "$max" ]; then
    say "lab $n LEFT OUT: its solution scores $got/$max from the bundle (${why:-see the report}): grading it needs the lab's own solution, which a Classroom 50 bundle cannot keep from students"
    rm -rf "$b"; left_out+=("$n"); continue
  fi
  say "lab $n: $(basename "$b") ($(du -sh "$b" | cut -f1)): the solution scores $got/$max through autograder.py in $secs s"
done
rm -f "$DEST/student-copy.log"

# The runtime: the kit's grading packages, printed by the kit script (the one list).
"$ROOT/kit" packages --grading | python3 -c '
import json, sys
packages = [line.strip() for line in sys.stdin if line.strip()]
json.dump({"runs-on": "ubuntu-latest", "apt": packages}, sys.stdout, indent=2)
print()' >"$DEST/runtime.json"
cp "$HERE/README.md" "$DEST/README.md"
[ -n "$(ls -A "$DEST/autograders")" ] || die "no lab could be bundled"
ok=1
[ ${#left_out[@]} -eq 0 ] || say "labs left out: ${left_out[*]} (see above); grade them on Gradescope or PrairieLearn, whose solutions stay private"
say "wrote $DEST: $(( ${#FOLDERS[@]} - ${#left_out[@]} )) bundle(s), runtime.json; release_assets: [\"kit-grade-report.html\"] (README.md)"
echo "$DEST"
[ ${#left_out[@]} -eq 0 ]
