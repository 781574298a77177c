#!/usr/bin/env bash
# grade_filtering_test.sh KIT_GRADE SOLUTIONS REFERENCES OUT_DIR: the solutions graded with
# llvmpipe's GPU-like texture filtering (GALLIVM_PERF=brilinear,rho_approx,no_quad_lod: the
# mip levels blended only near a level's midpoint, an approximate level of detail, one for
# each pixel) must keep full marks with the shipped references and their filter allowances
# (tools/grade/reference_store/references.h). Witness: the same render against a copy of the references
# without their allowances loses points, so the allowance holds the verdict, and the
# variable really changed llvmpipe's filtering.
set -euo pipefail
kit_grade="$1" solutions="$2" references="$3" out="$4"
rm -rf "$out" && mkdir -p "$out"
export GALLIVM_PERF=brilinear,rho_approx,no_quad_lod
export MESA_SHADER_CACHE_DISABLE=true  # programs compiled without GALLIVM_PERF are not reused
"$kit_grade" "$solutions" --out "$out/with" >"$out/with.log" 2>&1 || { cat "$out/with.log"; exit 1; }
cat "$out/with.log"
grep -q '"renderer": "[a-z]*: llvmpipe' "$out/with/summary.json" || { echo "not rendered by llvmpipe: GALLIVM_PERF is llvmpipe's"; exit 1; }
grep -Eq '^total: ([0-9.]+)/\1$' "$out/with.log" || { echo "the solutions lost points under GPU-like filtering (see $out/with/report.html)"; exit 1; }

cp -r "$references" "$out/references"
rm "$out/references/"*.allowance.exr
python3 - "$out/references/manifest.json" <<'PY'
import json, sys
path = sys.argv[1]
manifest = json.load(open(path))
manifest["filter_allowance"]["images"] = []
json.dump(manifest, open(path, "w"), indent=1)
PY
"$kit_grade" "$solutions" --labs 2-4 --references "$out/references" --out "$out/without" >"$out/without.log" 2>&1 || true
cat "$out/without.log"
if grep -q '^total: 30/30$' "$out/without.log"; then
  echo "witness failed: without the allowances the solutions still get 30/30 under GALLIVM_PERF=$GALLIVM_PERF"
  exit 1
fi
grep -q '^total: ' "$out/without.log" || { echo "witness failed: the run without allowances graded nothing"; exit 1; }
echo "ok: full marks with the filter allowances; without them labs 2-4 lose points"
