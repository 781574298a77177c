#!/usr/bin/env bash
# Regenerates the images the handouts show (handouts/images/*.png), 320x240.
# Called by `./kit handout-images`; also runs on its own. Headless (OSMesa,
# llvmpipe), so the output is the same on every run. Each kit-render call
# renders one frame and writes several views of it (--view/--out pairs).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RENDER="$ROOT/build/default/tools/kit-render"
OUT="$ROOT/handouts/images"
SIZE=320x240

if [[ ! -x "$RENDER" ]]; then
  echo "handout_images.sh: $RENDER not found; build first (./kit setup)" >&2
  exit 2
fi
export KIT_ROOT="$ROOT"
export KIT_SCENE_DIR="$ROOT/build/default/scenes"
mkdir -p "$OUT"

SOL="$ROOT/solutions"
LAB="$ROOT/labs"

# render SHADER_DIR STAGE SCENE [options and --view V --out NAME.png pairs]
# --out names are relative to handouts/images/.
render() {
  local shaders="$1" stage="$2" scene="$3"
  shift 3
  local args=()
  while (($#)); do
    if [[ "$1" == --out ]]; then
      args+=(--out "$OUT/$2"); shift 2
    else
      args+=("$1"); shift
    fi
  done
  "$RENDER" --backend osmesa --size "$SIZE" --shaders "$shaders" --stage "$stage" --scene "$scene" "${args[@]}"
}

# Lab 1: the G-buffer attachments (solution) and the starter's mistakes.
render "$SOL" gbuffer default \
  --view albedo --out lab1-solution-albedo.png \
  --view normal --out lab1-solution-normal.png \
  --view position --out lab1-solution-position.png \
  --view material --out lab1-solution-material.png \
  --view depth --out lab1-solution-depth.png
render "$LAB" gbuffer default \
  --view normal --out lab1-starter-normal.png \
  --view position --out lab1-starter-position.png

# Lab 2: Cook-Torrance lighting, clamped display (no falloff yet).
render "$SOL" lighting default --view final --out lab2-solution-default.png
render "$SOL" lighting sphere --view final --out lab2-solution-sphere.png
render "$LAB" lighting default --view final --out lab2-starter-default.png
render "$LAB" lighting sphere --view final --out lab2-starter-sphere.png

# Lab 3: falloff, Reinhard and gamma.
render "$SOL" attenuation default --view final --out lab3-solution.png
render "$LAB" attenuation default --view final --out lab3-starter.png
render "$SOL" attenuation default --gamma 0.5 --view final --out lab3-gamma-0.5.png
render "$SOL" attenuation default --gamma 1.0 --view final --out lab3-gamma-1.0.png
render "$SOL" attenuation default --gamma 2.5 --view final --out lab3-gamma-2.5.png
render "$SOL" attenuation default --attenuation physical --view final --out lab3-physical.png
render "$SOL" attenuation default --attenuation simple --view final --out lab3-simple.png

# Lab 4: normal mapping on the normalmap scene.
render "$SOL" normalmap normalmap \
  --view normal --out lab4-solution-normal.png \
  --view final --out lab4-solution-final.png
render "$LAB" normalmap normalmap \
  --view normal --out lab4-starter-normal.png \
  --view final --out lab4-starter-final.png

# Lab 5: bloom off / on, the custom effect, and the starter.
render "$SOL" postprocess default --postprocess off --view final --out lab5-postprocess-off.png
render "$SOL" postprocess default --postprocess on --view final --out lab5-postprocess-on.png
render "$SOL" postprocess default --postprocess on --custom on --view final --out lab5-custom-on.png
render "$LAB" postprocess default --postprocess on --view final --out lab5-starter.png

echo "handout images written to $OUT"
