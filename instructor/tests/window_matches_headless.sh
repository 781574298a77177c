#!/usr/bin/env bash
# The viewer shows what kit-render writes: for each stage, three frames in a
# kit-view window under Xvfb must give the same final image, pixel for pixel,
# as one headless kit-render frame, and the window's own pixels (the blitted
# view, no panel) must match it too.
#   window_matches_headless.sh KIT_VIEW KIT_RENDER WORK_DIR
set -euo pipefail

SIZE=320x240
STAGES=(gbuffer postprocess)
XVFB_SCREEN="-screen 0 1024x768x24"

fail() { echo "window_matches_headless: FAIL: $*" >&2; exit 1; }

[ $# -eq 3 ] || fail "usage: $0 KIT_VIEW KIT_RENDER WORK_DIR"
view="$1" render="$2" work="$3"
[ -x "$view" ] || fail "kit-view not found at '$view'"
[ -x "$render" ] || fail "kit-render not found at '$render'"
# A missing tool is a failure, never a skip: the window path would go untested.
for tool in xvfb-run xauth idiff oiiotool; do
  command -v "$tool" >/dev/null || fail "'$tool' is not installed (Debian: xvfb, xauth, openimageio-tools; ./kit setup installs them)"
done

rm -rf "$work"
mkdir -p "$work"
for stage in "${STAGES[@]}"; do
  window="$work/$stage-window-final.png"     # the renderer's final image, from the viewer
  shown="$work/$stage-window-pixels.png"     # what the window itself shows
  headless="$work/$stage-headless.png"
  # A visible window: a hidden one need not own its pixels, so its back buffer is undefined.
  xvfb-run -a -s "$XVFB_SCREEN" "$view" --solution --stage "$stage" --frames 3 --no-ui --size "$SIZE" \
    --screenshot "$window" --window-screenshot "$shown" || fail "kit-view --stage $stage exited with status $?"
  "$render" --solution --stage "$stage" --size "$SIZE" --out "$headless" || fail "kit-render --stage $stage exited with status $?"

  idiff "$window" "$headless" >"$work/$stage-final.idiff" 2>&1 ||
    fail "$stage: the viewer's final image differs from kit-render's:"$'\n'"$(cat "$work/$stage-final.idiff")"
  # The window has no meaningful alpha: compare colour only.
  oiiotool "$shown" --ch R,G,B -o "$work/$stage-window-rgb.png"
  oiiotool "$headless" --ch R,G,B -o "$work/$stage-headless-rgb.png"
  idiff "$work/$stage-window-rgb.png" "$work/$stage-headless-rgb.png" >"$work/$stage-pixels.idiff" 2>&1 ||
    fail "$stage: the window's pixels differ from kit-render's image:"$'\n'"$(cat "$work/$stage-pixels.idiff")"
  echo "window_matches_headless: $stage: viewer image and window pixels match kit-render ($SIZE)"
done
