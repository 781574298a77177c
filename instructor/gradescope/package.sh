#!/usr/bin/env bash
# ./kit gradescope-package [--labs 1,2,3] [--out FILE.zip]
#
# Builds the Gradescope autograder: a zip whose root holds setup.sh and
# run_autograder (Gradescope's two entry points), autograder.conf (the labs this
# assignment grades) and kit/, the kit's sources. Gradescope builds the kit once
# per image (setup.sh runs ./kit setup) and grades every submission with
# kit-grade (run_autograder). See instructor/gradescope/README.md.
#
# kit/ is every file git knows here, tracked or new but not ignored (so build/
# and out/ never go in), less big test fixtures (tests/fixtures/ files over
# 1 MiB: the autograder never runs the test suite). solutions/ is included on
# purpose: stages are assembled from earlier labs' solutions, and the grader
# compares against renders of them. Gradescope keeps the autograder private.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
OUT="$ROOT/out/gradescope/autograder.zip"
LABS=""  # empty: every lab of the kit (kit-grade's default)
FIXTURE_LIMIT=$((1024 * 1024))

say() { printf 'gradescope-package: %s\n' "$*" >&2; }
die() { say "$*"; exit 1; }

usage() {
  cat <<'USAGE'
usage: ./kit gradescope-package [--labs LIST] [--out FILE.zip]
  --labs LIST   labs this Gradescope assignment grades, comma separated (default: every lab);
                one lab per assignment lets students upload that lab's files on their own
  --out FILE    where to write the zip (default out/gradescope/autograder.zip)
USAGE
}

while [ $# -gt 0 ]; do
  case "$1" in
    --labs) [ $# -ge 2 ] || die "--labs needs a value"; LABS="$2"; shift 2 ;;
    --out) [ $# -ge 2 ] || die "--out needs a value"; OUT="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown option '$1'" ;;
  esac
done

if [ -n "$LABS" ]; then
  [[ "$LABS" =~ ^[0-9]+(,[0-9]+)*$ ]] || die "--labs expects lab numbers separated by commas (got '$LABS')"
  for n in ${LABS//,/ }; do
    ls -d "$ROOT/labs/$(printf '%02d' "$((10#$n))")"-* >/dev/null 2>&1 || die "--labs: the kit has no lab $n (labs/)"
  done
fi
command -v zip >/dev/null || die "zip is not installed (./kit setup installs it)"
case "$OUT" in /*) ;; *) OUT="$PWD/$OUT" ;; esac

# The kit's files: git's view when this is a checkout, else every file but build output.
list_files() {
  if git -C "$ROOT" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git -C "$ROOT" ls-files -z --cached --others --exclude-standard
  else
    (cd "$ROOT" && find . -path ./build -prune -o -path ./out -prune -o -path ./.git -prune \
       -o -type f -print0 | sed -z 's|^\./||')
  fi
}

STAGE="$(mktemp -d)"
trap 'rm -rf "$STAGE"' EXIT
mkdir -p "$STAGE/kit"

count=0
skipped=()
files=()
while IFS= read -r -d '' f; do
  case "$f" in build/*|out/*|.git/*) continue ;; esac
  if [ ! -f "$ROOT/$f" ] || [ -L "$ROOT/$f" ]; then continue; fi  # deleted but still in git's index, or a link
  if [[ "$f" == tests/fixtures/* ]] && [ "$(stat -c %s "$ROOT/$f")" -gt "$FIXTURE_LIMIT" ]; then
    skipped+=("$f")
    continue
  fi
  files+=("$f")
  count=$((count + 1))
done < <(list_files | sort -zu)
# One cp for them all, each under its own path (a process per file took most of the package's time).
[ "$count" -eq 0 ] || (cd "$ROOT" && printf '%s\0' "${files[@]}" | xargs -0 cp -p --parents -t "$STAGE/kit")

[ -x "$STAGE/kit/kit" ] || die "the kit script is missing from the file list (is $ROOT the kit?)"
for needed in solutions shaders tools/grade; do
  [ -d "$STAGE/kit/$needed" ] || die "$needed/ is missing from the file list: the autograder cannot grade without it"
done

install -m 0755 "$HERE/setup.sh" "$STAGE/setup.sh"
install -m 0755 "$HERE/run_autograder" "$STAGE/run_autograder"
cat >"$STAGE/autograder.conf" <<CONF
# Read by run_autograder (an environment variable of the same name wins).
# Written by ./kit gradescope-package${LABS:+ --labs $LABS} (empty: every lab)
KIT_LABS=$LABS
CONF

mkdir -p "$(dirname "$OUT")"
rm -f "$OUT"
(cd "$STAGE" && zip -q -r -X "$OUT" setup.sh run_autograder autograder.conf kit)

say "$count kit files, labs ${LABS:-(every lab)}$([ ${#skipped[@]} -gt 0 ] && echo ", ${#skipped[@]} big fixture(s) left out")"
say "wrote $OUT ($(du -h "$OUT" | cut -f1)); upload it as the assignment's autograder (README: instructor/gradescope/README.md)"
echo "$OUT"
