#!/usr/bin/env bash
# instructor/grading/gpu_check.sh [BUILD_DIR]: grades the reference solutions and runs the
# mistake catalogue's self-check on the machine's GPU (kit-grade --gpu --backend egl), and
# prints one table: what rendered, each lab's score with the checks it lost and by how
# many pixels, and the self-check's verdict. For a machine with a GPU; on one without, it
# grades on whatever EGL device comes first (Mesa's software rasteriser), which shows the
# script works but measures no GPU. docs/grading.md ("The same grade on any computer")
# holds the table of the last GPU run. BUILD_DIR defaults to build/default.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build/default}"
GRADE="$BUILD/tools/kit-grade"
[ -x "$GRADE" ] || { echo "gpu_check: $GRADE is not built (./kit setup)" >&2; exit 2; }
export KIT_SCENE_DIR="${KIT_SCENE_DIR:-$BUILD/scenes}"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/kit-gpu-check-XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

# The self-check runs kit-grade itself: a wrapper adds the GPU flags to every run.
cat >"$WORK/kit-grade" <<WRAPPER
#!/bin/sh
exec "$GRADE" "\$@" --gpu --backend egl
WRAPPER
chmod +x "$WORK/kit-grade"

start=$SECONDS
"$WORK/kit-grade" "$ROOT/solutions" --out "$WORK/solutions" >"$WORK/solutions.log" 2>&1 || true
python3 - "$WORK/solutions/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"renderer: {s.get('renderer', '?')} (device: {s.get('device', '?')})")
print(f"within the measured implementations: {s.get('within_measured_implementations')}")
print("| lab | score | checks lost (failing pixels / allowed, largest error) |")
print("|---|---|---|")
for number, lab in sorted(s["labs"].items(), key=lambda item: int(item[0])):
    lost = [f"{key} ({c['failing_pixels']}/{c['allowed_failing_pixels']}, {c['max_error']:.3g})"
            for key, c in lab.get("checks", {}).items() if not c["passed"]]
    status = "" if lab["status"] == "graded" else f" [{lab['status']}]"
    print(f"| {number} {lab['name']} | {lab['score']:g}/{lab['max_score']:g}{status} | {', '.join(lost) or '-'} |")
print(f"total: {s['total']:g}/{s['max_total']:g}")
PY
echo
if [ -d "$ROOT/instructor/grading" ]; then
  python3 "$ROOT/instructor/grading/self_check.py" --kit-grade "$WORK/kit-grade" >"$WORK/self_check.log" 2>&1 &&
    verdict="passes" || verdict="FAILS"
  echo "self-check on the GPU: $verdict; its summary:"
  tail -n 6 "$WORK/self_check.log"
fi
echo "gpu_check: $((SECONDS - start)) s"
