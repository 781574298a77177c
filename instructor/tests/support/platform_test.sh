# Sourced by the platform tests (gradescope_test.sh, prairielearn_test.sh,
# classroom50_test.sh, platforms_test.sh), each run as `TEST.sh PATH/TO/kit-grade`:
# GRADER (that kit-grade), ROOT (the kit), PY (Debian's python3), TMP (removed at exit),
# and fail/pass/finish to report checks.
set -euo pipefail

TEST_NAME="$(basename "$0" _test.sh)"
GRADER="$(realpath "${1:?usage: $(basename "$0") PATH/TO/kit-grade}")"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
PY=/usr/bin/python3
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
failures=0
fail() { printf 'FAIL: %s\n' "$*"; failures=$((failures + 1)); }
pass() { printf 'ok: %s\n' "$*"; }
# The last line: every check passed (exit 0), or how many failed (exit 1).
finish() {
  if [ "$failures" -gt 0 ]; then echo "$TEST_NAME: $failures check(s) failed"; exit 1; fi
  echo "$TEST_NAME: every check passed"
}
