#!/usr/bin/env bash
# instructor/test_cpu.py on a ctest of its own (a folder with one test that burns 1.5 s of CPU,
# so the kit's own ctest log is not touched): the test is named by its ctest name with at
# least a second of CPU, and the run's total is printed.
# usage: test_cpu_test.sh WORK_DIR
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
WORK="$1"
rm -rf "$WORK" && mkdir -p "$WORK"
PY=/usr/bin/python3  # a program, not a shim that execs another (pyenv): the tool names a test by its command
cat >"$WORK/CTestTestfile.cmake" <<CMAKE
add_test(cpu_burner "$PY" "-c" "import time
t = time.process_time()
while time.process_time() - t < 1.5: pass")
CMAKE
out="$("$PY" "$ROOT/instructor/test_cpu.py" --build "$WORK" -- ctest --test-dir "$WORK")"
echo "$out"
grep -Eq '^\| [12] \| [0-9]+ \| `cpu_burner` \|$' <<<"$out" || { echo "FAIL: cpu_burner is not listed with 1 or 2 CPU seconds"; exit 1; }
grep -Eq 'exit 0, [0-9]+ s wall, [0-9]+ s of CPU in all' <<<"$out" || { echo "FAIL: no total line"; exit 1; }
echo "ok: the test named, with its CPU seconds"
