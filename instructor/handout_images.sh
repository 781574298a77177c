#!/usr/bin/env bash
# Regenerates the images the handouts show: handouts/images/*.png, 320x240 RGB (lab 6's
# maps and environments at their own shapes).
# Called by `./kit handout-images`; also runs on its own from any directory.
#
# Everything is rendered headlessly by the default build's kit-render on the OSMesa
# backend (llvmpipe), so the output is the same on every run. Besides the solutions
# and the starters, a few images show a typical mistake: the script copies a solution
# file into a temporary folder and changes one line in it (`mistake` below), so the
# handouts can show what that mistake looks like. If a solution is rewritten so that
# the line is no longer there, the script stops and names it. Lab 6's maps (the BRDF
# table, the prefiltered and irradiance maps) are floats at their own sizes: the script
# tone-maps and enlarges them with oiiotool.
#
# The images are rendered into a temporary folder and replace handouts/images/*.png
# only when every one of them was made, and then only those whose bytes changed.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${KIT_BUILD_DIR:-$ROOT/build/default}"  # another build's programs, on this kit's files (./kit rebaseline --build)
# kit-render through its huge-page launcher (tools/launcher/), as ./kit render and ./kit demo
# run it: the script took 25.8 s of CPU against 30.7 s (median of 3 interleaved runs,
# farm-bench), the images byte-identical.
RENDER="$BUILD/tools/kit-render-hugepages"
OUT="$ROOT/handouts/images"
SIZE=320x240
SOL="$ROOT/solutions"
LAB="$ROOT/labs"

die() { echo "handout_images.sh: $*" >&2; exit 1; }
[[ -x "$RENDER" ]] || die "$RENDER not found; build first (./kit setup)"
command -v oiiotool >/dev/null || die "oiiotool not found (Debian package openimageio-tools)"

export KIT_ROOT="$ROOT"
export KIT_SCENE_DIR="$BUILD/scenes"
TMP="$(mktemp -d "${TMPDIR:-/tmp}/handout-images.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT
RAW="$TMP/raw"    # kit-render's output (RGBA, maybe larger than 320x240)
VIEWS="$RAW/views" # lab 6's maps as kit-render writes them (floats at their own sizes), made into pictures in $RAW
NEW="$TMP/images" # the finished images
mkdir -p "$RAW" "$VIEWS" "$NEW"

# --- Jobs: up to `nproc` renders at once (llvmpipe uses every core anyway, but the
# shader compile and PNG writing of one render are single-threaded). ---
MAX_JOBS="$(nproc 2>/dev/null || echo 2)"
PIDS=()
FAILED=0
spawn() {
  if ((${#PIDS[@]} >= MAX_JOBS)); then
    wait "${PIDS[0]}" || FAILED=1
    PIDS=("${PIDS[@]:1}")
  fi
  "$@" &
  PIDS+=($!)
}
wait_all() {
  local pid
  for pid in "${PIDS[@]}"; do wait "$pid" || FAILED=1; done
  PIDS=()
  ((FAILED == 0)) || die "a render failed (see the messages above)"
}

# render SHADER_DIR STAGE SCENE [kit-render options, --view V --out NAME.png pairs]
# Renders one frame at $SIZE unless the options give --size; --out names are file
# names only (written to $RAW; finish_all turns them into the handout images).
render() {
  local shaders="$1" stage="$2" scene="$3"
  shift 3
  local args=(--size "$SIZE")
  while (($#)); do
    if [[ "$1" == --out ]]; then
      args+=(--out "$RAW/$2"); shift 2
    else
      args+=("$1"); shift
    fi
  done
  "$RENDER" --shaders "$shaders" --stage "$stage" --scene "$scene" "${args[@]}"
}

# render_crop CROP SHADER_DIR STAGE SCENE --size WxH [options] --view V --out NAME.png
# As render, but the image is cut to CROP (oiiotool geometry WxH+X+Y), so a detail shows
# at its rendered resolution instead of being scaled.
render_crop() {
  local crop="$1" args=("${@:2}") i
  render "${args[@]}"
  for ((i = 0; i < ${#args[@]}; i++)); do
    [[ "${args[i]}" == --out ]] && echo "$crop" >"$RAW/${args[i + 1]}.cut"
  done
  return 0
}

# One oiiotool run for every image (it takes ~0.3 s just to start): drop the alpha
# channel (always 1), apply the cuts, compress.
finish_all() {
  local args=() f name
  for f in "$RAW"/*.png; do
    name="$(basename "$f")"
    args+=("$f")
    [[ -f "$f.cut" ]] && args+=(--cut "$(<"$f.cut")")
    args+=(--ch "R,G,B" --attrib png:compressionLevel 9 -o "$NEW/$name")
  done
  oiiotool --nosoftwareattrib "${args[@]}"
}

# mistake DEST_ROOT CATALOGUE_ID
# Writes the entry's lab folder (solutions/NN-name/ with the entry's edits) to
# DEST_ROOT/NN-name/: the mistakes shown are entries of instructor/grading/catalogue.json,
# the same the grader's self-check proves it catches. Stops if an edit is stale.
mistake() {
  python3 "$ROOT/instructor/grading/self_check.py" --solutions "$SOL" --write "$2" "$1" ||
    die "catalogue entry '$2' no longer applies to the solutions: update the mistake images"
}

# A kit root (shaders/ + solutions/) whose earlier-lab solution carries a mistake,
# for showing a lab-2 mistake through lab 3's tone mapping (stages after N take
# labs 1..N from KIT_ROOT/solutions).
mistake_root() {
  local dest="$1"
  mkdir -p "$dest/solutions"
  cp -r "$ROOT/shaders" "$dest/shaders"
  cp -r "$SOL/01-gbuffer" "$dest/solutions/"
  shift
  mistake "$dest/solutions" "$@"
}

# edit_solution DEST_ROOT NN-name FILE FIND REPLACE [FIND REPLACE ...]
# Writes solutions/NN-name/ to DEST_ROOT/NN-name/ with each FIND text of FILE (it must
# occur exactly once) replaced: the mistakes of lab 6, which the grader's catalogue does
# not cover yet. Stops, naming the text, when the solution no longer holds it.
edit_solution() {
  local dest="$1" folder="$2" file="$3"
  shift 3
  mkdir -p "$dest" && cp -r "$SOL/$folder" "$dest/"
  python3 - "$dest/$folder/$file" "$@" <<'PY' || die "solutions/$folder/$file changed: update the lab 6 mistake images"
import sys
path, edits = sys.argv[1], sys.argv[2:]
text = open(path, encoding="utf-8").read()
for find, replace in zip(edits[::2], edits[1::2]):
    if text.count(find) != 1:
        sys.exit(f"handout_images.sh: '{find}' occurs {text.count(find)} times in {path}, not once")
    text = text.replace(find, replace)
open(path, "w", encoding="utf-8").write(text)
PY
}

# with_kit_root DIR COMMAND...: COMMAND with KIT_ROOT=DIR (spawn runs it in a subshell).
with_kit_root() {
  export KIT_ROOT="$1"
  shift
  "$@"
}

# --- The mistakes shown (one changed line each; ids in instructor/grading/catalogue.json) ---
mistake "$TMP/m-model-matrix" gbuffer-normal-model-matrix
mistake_root "$TMP/m-alpha-root" lighting-alpha-is-roughness
mistake "$TMP/m-double-gamma" tonemap-gamma-applied-twice
mistake "$TMP/m-handedness" normalmap-handedness-ignored
mistake "$TMP/m-tangent-space" normalmap-left-in-tangent-space
mistake "$TMP/m-horizontal" postprocess-blur-horizontal-only
mistake "$TMP/m-front-faces" lightvolumes-front-faces-drawn
# Lab 6: each sample read from level 0 (no filtered importance sampling), and the BRDF
# table without its n.v guards (n.v = 0 in the first column makes the weight 0/0).
edit_solution "$TMP/m-prefilter-level0" 06-ibl prefilter.frag \
  'float level = max(0.5 * log2(sample_solid_angle / texel_solid_angle) + 1.0, 0.0);' 'float level = 0.0;'
edit_solution "$TMP/m-brdf-no-guard" 06-ibl brdf_lut.frag \
  'float n_dot_v = max(kit_brdf_lut_grid_value(v_uv.x), KIT_MIN_N_DOT_V);' \
  'float n_dot_v = kit_brdf_lut_grid_value(v_uv.x);' \
  'float weight = g * v_dot_h / max(n_dot_h * n_dot_v, KIT_MIN_DENOMINATOR);' \
  'float weight = g * v_dot_h / (n_dot_h * n_dot_v);'

# A floor with three 1.5 cd point lights 10 cm, 40 cm and 1 m above it (left to right):
# where the physical and the simple falloff differ (the kit's scenes keep their lights
# 2-6 m from every surface, where the two models nearly agree).
FALLOFF="$TMP/falloff.gltf"
cat >"$FALLOFF" <<'GLTF'
{"asset":{"version":"2.0","generator":"instructor/handout_images.sh"},"extensionsUsed":["KHR_lights_punctual"],
 "extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","color":[1,1,1],"intensity":1.5}]}},
 "buffers":[{"byteLength":120,"uri":"data:application/octet-stream;base64,AAAgwQAAAAAAACBBAAAgQQAAAAAAACBBAAAgQQAAAAAAACDBAAAgwQAAAAAAACDBAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAEAAAACAAAAAAAAAAIAAAADAAAA"}],
 "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48,"target":34962},{"buffer":0,"byteOffset":48,"byteLength":48,"target":34962},
                {"buffer":0,"byteOffset":96,"byteLength":24,"target":34963}],
 "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-10,0,-10],"max":[10,0,10]},
              {"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"},{"bufferView":2,"componentType":5125,"count":6,"type":"SCALAR"}],
 "materials":[{"name":"grey","pbrMetallicRoughness":{"baseColorFactor":[0.8,0.8,0.8,1],"metallicFactor":0.0,"roughnessFactor":0.7}}],
 "meshes":[{"name":"floor","primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2,"material":0}]}],
 "cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1,"zfar":50}}],
 "nodes":[{"name":"floor","mesh":0},{"name":"camera","camera":0,"translation":[0,2.2,3.6],"rotation":[-0.259397,0,0,0.965771]},
          {"name":"light_10cm","translation":[-1.6,0.1,0],"extensions":{"KHR_lights_punctual":{"light":0}}},
          {"name":"light_40cm","translation":[0,0.4,0],"extensions":{"KHR_lights_punctual":{"light":0}}},
          {"name":"light_100cm","translation":[1.6,1.0,0],"extensions":{"KHR_lights_punctual":{"light":0}}}],
 "scenes":[{"nodes":[0,1,2,3,4]}],"scene":0}
GLTF

# --- Lab 1: the G-buffer views (solution), the starter, the normal-matrix mistake ---
spawn render "$SOL" gbuffer default \
  --view albedo --out lab1-solution-albedo.png \
  --view normal --out lab1-solution-normal.png \
  --view position --out lab1-solution-position.png \
  --view material --out lab1-solution-material.png \
  --view depth --out lab1-solution-depth.png
spawn render "$LAB" gbuffer default \
  --view albedo --out lab1-starter-albedo.png \
  --view normal --out lab1-starter-normal.png \
  --view position --out lab1-starter-position.png \
  --view material --out lab1-starter-material.png
spawn render "$SOL" gbuffer normalmap --view normal --out lab1-solution-normal-normalmap.png
spawn render "$TMP/m-model-matrix" gbuffer normalmap --view normal --out lab1-mistake-model-matrix.png

# --- Lab 2: Cook-Torrance, no falloff yet, clamped display ---
spawn render "$SOL" lighting default --out lab2-solution-default.png
spawn render "$SOL" lighting sphere --out lab2-solution-sphere.png
spawn render "$LAB" lighting default --out lab2-starter-default.png
spawn render "$LAB" lighting sphere --out lab2-starter-sphere.png
# alpha = roughness vs roughness^2, seen through lab 3's falloff and tone mapping:
# the sphere rows, roughness 0 to 0.75 (a 320x240 cut of a 640x480 frame).
spawn render_crop 320x240+120+140 "$SOL" attenuation default --size 640x480 --out lab2-roughness-squared.png
spawn with_kit_root "$TMP/m-alpha-root" \
  render_crop 320x240+120+140 "$SOL" attenuation default --size 640x480 --out lab2-mistake-alpha-roughness.png

# --- Lab 3: falloff, Reinhard, gamma ---
spawn render "$SOL" attenuation default --out lab3-solution.png
spawn render "$LAB" attenuation default --out lab3-starter.png
for g in 0.5 1.0 2.5; do
  spawn render "$SOL" attenuation default --gamma "$g" --out "lab3-gamma-$g.png"
done
spawn render "$SOL" attenuation default --attenuation physical --out lab3-physical.png
spawn render "$SOL" attenuation default --attenuation simple --out lab3-simple.png
spawn render "$SOL" attenuation "$FALLOFF" --attenuation physical --out lab3-falloff-physical.png
spawn render "$SOL" attenuation "$FALLOFF" --attenuation simple --out lab3-falloff-simple.png
spawn render "$TMP/m-double-gamma" attenuation default --out lab3-mistake-double-gamma.png

# --- Lab 4: normal mapping ---
spawn render "$SOL" normalmap normalmap --view normal --out lab4-solution-normal.png --view final --out lab4-solution-final.png
spawn render "$LAB" normalmap normalmap --view normal --out lab4-starter-normal.png --view final --out lab4-starter-final.png
spawn render "$SOL" normalmap default --out lab4-solution-default.png
spawn render "$LAB" normalmap default --out lab4-starter-default.png
spawn render "$TMP/m-tangent-space" normalmap normalmap --view normal --out lab4-mistake-tangent-space-normal.png \
  --view final --out lab4-mistake-tangent-space-final.png
# The mirrored (right) quad of the normalmap scene, a 320x240 cut of a 1280x960 frame.
spawn render_crop 320x240+664+300 "$SOL" normalmap normalmap --size 1280x960 --view normal --out lab4-mirrored-solution.png
spawn render_crop 320x240+664+300 "$TMP/m-handedness" normalmap normalmap --size 1280x960 --view normal --out lab4-mistake-handedness.png

# --- Lab 5: bloom, the toggle, thresholds, the custom effect ---
spawn render "$SOL" postprocess default --postprocess off --out lab5-postprocess-off.png
spawn render "$SOL" postprocess default --postprocess on --out lab5-postprocess-on.png
spawn render "$SOL" postprocess default --custom on --out lab5-custom-on.png
spawn render "$SOL" postprocess default --threshold 0.5 --out lab5-threshold-0.5.png
spawn render "$SOL" postprocess default --threshold 4 --out lab5-threshold-4.png
spawn render "$LAB" postprocess default --out lab5-starter.png
spawn render "$TMP/m-horizontal" postprocess default --out lab5-mistake-horizontal-only.png

# --- Lab 6: image-based lighting (the stage runs lab 5's bloom as well) ---
spawn render "$SOL" ibl default --environment studio --out lab6-solution-studio.png
spawn render "$SOL" ibl default --environment sun --out lab6-solution-sun.png \
  --view brdf-lut --out views/lab6-brdf-lut.png --view prefiltered --out views/lab6-prefiltered-sun.exr \
  --view irradiance --out views/lab6-irradiance-sun.exr
spawn render "$LAB" ibl default --environment studio --out lab6-starter.png
spawn render "$SOL" ibl sphere --environment sun --out lab6-solution-sphere-sun.png
# The sun's reflection on the sphere's upper right, a 320x240 cut of a 640x480 frame.
spawn render_crop 320x240+290+40 "$SOL" ibl sphere --environment sun --size 640x480 --out lab6-prefilter-detail.png
spawn render_crop 320x240+290+40 "$TMP/m-prefilter-level0" ibl sphere --environment sun --size 640x480 \
  --out lab6-mistake-prefilter-level0.png
spawn render "$TMP/m-prefilter-level0" ibl sphere --environment sun \
  --view prefiltered --out views/lab6-mistake-prefiltered-level0.exr
# --check-maps off: the kit would stop at the table's NaN; this shows what it would do.
spawn render "$TMP/m-brdf-no-guard" ibl sphere --environment sun --check-maps off --out lab6-mistake-brdf-no-guard.png

# --- Lab 7: light volumes (the stage runs lab 5's bloom; no environment) ---
spawn render "$SOL" lightvolumes lights --out lab7-solution-lights.png
spawn render "$LAB" lightvolumes lights --out lab7-starter-lights.png
spawn render "$SOL" lightvolumes inside --out lab7-solution-inside.png
spawn render "$TMP/m-front-faces" lightvolumes inside --out lab7-mistake-front-faces.png

wait_all

# Lab 6's maps as pictures. Radiance is tone-mapped as the kit's display does it
# (Reinhard c/(1+c), then gamma 2.2); irradiance E is shown as E/pi, the radiance a white
# diffuse surface reflects, so it reads on the environment's scale. The BRDF table is
# already in [0, 1]: shown as kit-render writes it, enlarged without smoothing.
TONEMAP=(--dup --addc 1 --div --powc 0.454545)
# An EXR's date and linear colour space would follow it into the PNG (a changing date, and
# a gAMA chunk telling viewers the gamma-encoded values are linear).
AS_SRGB=(--eraseattrib DateTime --eraseattrib oiio:Gamma --iscolorspace sRGB)
ENVIRONMENTS="$KIT_SCENE_DIR/environments"
# prefiltered_grid VIEW.exr OUT.png: the 'prefiltered' view (its KIT_PREFILTER_LEVELS = 6
# levels stacked top to bottom, level 0 first) as a 2x3 grid of 160x80 tiles, row by row.
prefiltered_grid() {
  local in="$1" out="$2" width level top=0 args=()
  width="$(oiiotool "$in" --echo '{TOP.width}')"
  for ((level = 0; level < 6; level++)); do
    args+=(-i "$in" --cut "$((width >> level))x$((width >> (level + 1)))+0+$top" --resample 160x80)
    top=$((top + (width >> (level + 1))))
  done
  oiiotool --nosoftwareattrib "${args[@]}" --mosaic 2x3 --ch R,G,B "${TONEMAP[@]}" "${AS_SRGB[@]}" -d uint8 -o "$RAW/$out"
}
for name in studio sun; do
  spawn oiiotool --nosoftwareattrib "$ENVIRONMENTS/$name.exr" --ch R,G,B "${TONEMAP[@]}" --resize 320x160 \
    "${AS_SRGB[@]}" -d uint8 -o "$RAW/lab6-environment-$name.png"
done
spawn oiiotool --nosoftwareattrib "$VIEWS/lab6-irradiance-sun.exr" --ch R,G,B --mulc 0.3183099 "${TONEMAP[@]}" \
  --resample 320x160 "${AS_SRGB[@]}" -d uint8 -o "$RAW/lab6-irradiance-sun.png"
spawn prefiltered_grid "$VIEWS/lab6-prefiltered-sun.exr" lab6-prefiltered-sun.png
spawn prefiltered_grid "$VIEWS/lab6-mistake-prefiltered-level0.exr" lab6-mistake-prefiltered-level0.png
spawn oiiotool --nosoftwareattrib "$VIEWS/lab6-brdf-lut.png" --ch R,G,B --resample:interp=0 256x256 \
  -o "$RAW/lab6-brdf-lut.png"
# The table's channels A, B, C apart, as grey, 128x128 each.
spawn oiiotool --nosoftwareattrib -i "$VIEWS/lab6-brdf-lut.png" --ch R=R,G=R,B=R --resample:interp=0 128x128 \
  -i "$VIEWS/lab6-brdf-lut.png" --ch R=G,G=G,B=G --resample:interp=0 128x128 \
  -i "$VIEWS/lab6-brdf-lut.png" --ch R=B,G=B,B=B --resample:interp=0 128x128 \
  --mosaic:pad=6 3x1 -o "$RAW/lab6-brdf-lut-abc.png"

wait_all
finish_all

# Only the images whose bytes changed are replaced (and those no longer made removed), so that
# a run after a change that moved no pixel leaves the folder as it was (./kit rebaseline).
mkdir -p "$OUT"
made=("$NEW"/*.png)
changed=0
for f in "$OUT"/*.png; do
  [ -e "$f" ] && [ ! -e "$NEW/$(basename "$f")" ] && { rm -f "$f"; changed=$((changed + 1)); }
done
for f in "${made[@]}"; do
  cmp -s "$f" "$OUT/$(basename "$f")" || { cp "$f" "$OUT/"; changed=$((changed + 1)); }
done
echo "handout_images.sh: ${#made[@]} images in $OUT, $changed changed"
