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
    --screenshot "$window" --window-screenshot "$shown" --timings >"$work/$stage-timings.txt" ||
    fail "kit-view --stage $stage exited with status $?"
  # Nothing changed after the first frame: the other two show it again, unrendered.
  grep -q "3 frames, 1 rendered" "$work/$stage-timings.txt" ||
    fail "$stage: a still viewer rendered more than its first frame:"$'\n'"$(cat "$work/$stage-timings.txt")"
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

# While the camera moves (--spin turns it every frame but the last), frames are
# rendered at half the width and height; the still last frame is full size, and
# the window shows that full-size image, not the smaller one scaled up.
moved="$work/spin-final.png" moved_shown="$work/spin-window-pixels.png"
xvfb-run -a -s "$XVFB_SCREEN" "$view" --solution --stage postprocess --frames 4 --no-ui --size "$SIZE" --spin \
  --timings --screenshot "$moved" --window-screenshot "$moved_shown" >"$work/spin-timings.txt" ||
  fail "kit-view --spin exited with status $?"
half="$((${SIZE%x*} / 2))x$((${SIZE#*x} / 2))"
grep -q "4 frames, 4 rendered (2 while moving at $half, 2 still at $SIZE)" "$work/spin-timings.txt" ||
  fail "--spin: expected the 2 middle frames at $half and the first and last at $SIZE:"$'\n'"$(cat "$work/spin-timings.txt")"
size="$(oiiotool --info "$moved" | grep -o '[0-9]* x *[0-9]*' | head -1 | tr -d ' ')"
[ "$size" = "$SIZE" ] || fail "--spin: the last (still) frame is $size, not the window's $SIZE"
oiiotool "$moved_shown" --ch R,G,B -o "$work/spin-window-rgb.png"
oiiotool "$moved" --ch R,G,B -o "$work/spin-final-rgb.png"
idiff "$work/spin-window-rgb.png" "$work/spin-final-rgb.png" >"$work/spin-pixels.idiff" 2>&1 ||
  fail "--spin: the window does not show the still frame's full-size image:"$'\n'"$(cat "$work/spin-pixels.idiff")"
echo "window_matches_headless: moving frames at $half, the still frame at $SIZE is what the window shows"
