#!/usr/bin/env bash
# grade_softpipe_test.sh KIT_GRADE SOLUTIONS OUT_DIR: the solutions of labs 1-5 graded on softpipe
# (the caller sets GALLIUM_DRIVER=softpipe) must get 50/50, and the run must say softpipe
# rendered it, so that a machine where the variable did nothing cannot pass for one.
set -euo pipefail
kit_grade="$1" solutions="$2" out="$3"
rm -rf "$out" && mkdir -p "$out"
"$kit_grade" "$solutions" --labs 1-5 --out "$out" >"$out/grade.log" 2>&1 || { cat "$out/grade.log"; exit 1; }
cat "$out/grade.log"
grep -q '"renderer": "[a-z]*: softpipe' "$out/summary.json" || { echo "not rendered by softpipe"; exit 1; }
grep -q '^total: 50/50$' "$out/grade.log" || { echo "the solutions lost points on softpipe (see $out/report.html)"; exit 1; }
