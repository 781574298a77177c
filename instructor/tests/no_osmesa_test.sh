#!/usr/bin/env bash
# The kit without OSMesa (Mesa 25.1 and later have none): configured with -DKIT_OSMESA=OFF,
# which builds as if libosmesa6-dev were missing, the programs link no OSMesa, render
# through EGL by default, refuse --backend osmesa by name, write the same image as this
# build's default backend, and grade the solutions of labs 1-3 at full marks.
#   no_osmesa_test.sh SOURCE_DIR MAIN_BUILD_DIR WORK_DIR
set -euo pipefail
src="$1" main="$2" work="$3"
build="$work/build"
fail() { echo "no_osmesa: $*" >&2; exit 1; }
mkdir -p "$work"
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKIT_GRADING_ONLY=ON -DKIT_OSMESA=OFF \
  >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; fail "configure failed"; }
grep -q "kit: OSMesa OFF" "$work/configure.log" || fail "the configure summary does not say 'OSMesa OFF'"
cmake --build "$build" --target kit-render kit-grade-main >"$work/build.log" 2>&1 ||
  { tail -n 40 "$work/build.log"; fail "build failed"; }
render="$build/tools/kit-render"
if ldd "$render" | grep -i osmesa; then fail "kit-render links OSMesa"; fi

export KIT_SCENE_DIR="$main/scenes"  # this build makes no scenes of its own (kit-scenes is not built)
args=(--solution --stage attenuation --size 160x120)
output="$("$render" "${args[@]}" --out "$work/default.png" --timings 2>&1)" || fail "kit-render failed: $output"
grep -q "(egl: " <<<"$output" || fail "the default backend is not egl: $output"
if output="$("$render" "${args[@]}" --backend osmesa --out "$work/osmesa.png" 2>&1)"; then
  fail "--backend osmesa was accepted: $output"
fi
grep -q "this build of the kit has no OSMesa" <<<"$output" || fail "--backend osmesa: unclear refusal: $output"

# The same frame from the main build's default backend (OSMesa where it has it): identical bytes.
"$main/tools/kit-render" "${args[@]}" --out "$work/main.png" >/dev/null 2>&1 || fail "the main build's kit-render failed"
cmp -s "$work/default.png" "$work/main.png" || fail "EGL without OSMesa and the main build's render differ"

"$build/tools/kit-grade-main" "$src/solutions" --labs 1-3 --out "$work/grade" \
  >"$work/grade.log" 2>&1 || { cat "$work/grade.log"; fail "kit-grade failed"; }
grep -q "^total: 30/30" "$work/grade.log" || { cat "$work/grade.log"; fail "the solutions of labs 1-3 lost points"; }
echo "no_osmesa: built without OSMesa; EGL by default, osmesa refused, the same image, labs 1-3 at 30/30"
