#!/usr/bin/env bash
# instructor/grading/measure.sh [BUILD_DIR]: how fast and how big kit-grade is.
#
# Measures (not a test: numbers depend on the machine and its load):
#   1. one full submission (solutions/) at --jobs 1 and --jobs 2, cold (no Mesa
#      shader seed: the cache emptied before each run, median of 3; the references
#      as the build prepared them, and at --jobs 2 without them too) and warm (the
#      shader seed --check-references writes, as in the Gradescope image, median
#      of 5): wall, CPU (user+sys of kit-grade and its children) and peak memory
#      (largest single process from /usr/bin/time -v, and the peak sum of
#      proportional set sizes of all kit-grade processes, sampled every 10 ms in a
#      run of its own);
#   2. batch throughput for 20 submissions (10 solutions, 10 starters) at --jobs 2;
#   3. where the time goes: the parent's fixed cost (an empty submission renders
#      nothing), the CPU of the grading process against its render workers', and
#      per lab its share of its worker (context: only a worker's first lab makes one;
#      compile, render and read-back; peaks: the worker's up to that lab's end) and the
#      parent's comparison (from summary.json); then per scene (each Renderer of a lab)
#      its setup (programs, targets, the scene's upload, lab 6's maps) against its
#      frames, warm and cold, from the labs' child.json of a run kept with --keep-temp.
# BUILD_DIR defaults to build/default. Prints a report; leaves nothing behind.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${1:-$ROOT/build/default}"
GRADE="$BUILD/tools/kit-grade"
PY=/usr/bin/python3
[ -x "$GRADE" ] || { echo "measure: $GRADE not built" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "measure: /usr/bin/time missing (apt-get install time)" >&2; exit 2; }
export KIT_SCENE_DIR="$BUILD/scenes"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/kit-grade-measure-XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), $(uname -r)"

# measure LABEL RUNS SETUP CMD...: SETUP (shell code: empty the cache for a cold run), then
# CMD once beside a PSS sampler, for memory only (the sampler, Python reading /proc every
# 10 ms, takes CPU from the run it watches), then RUNS times under /usr/bin/time -v alone:
# the medians of wall and CPU. Prints one line; $WORK/time-LABEL and the command's output
# folder are the last timed run's.
measure() {
  local label="$1" runs="$2" setup="$3"; shift 3
  local i
  eval "$setup"
  "$PY" - "$WORK/pss-$label" "$WORK" <<'EOF' &
import os, sys, time
# Peak sum of Pss over this script's kit-grade processes: their command line
# names the work folder (forked render workers keep the parent's).
peak = 0
deadline = time.time() + 600
while time.time() < deadline and not os.path.exists(sys.argv[1] + ".stop"):
    total = 0
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                args = f.read().split(b"\0")
            if b"kit-grade" not in args[0] or not any(sys.argv[2].encode() in a for a in args):
                continue
            with open(f"/proc/{pid}/smaps_rollup") as f:
                for line in f:
                    if line.startswith("Pss:"):
                        total += int(line.split()[1])
        except OSError:
            pass
    peak = max(peak, total)
    time.sleep(0.01)
open(sys.argv[1], "w").write(str(peak))
EOF
  local sampler=$!
  /usr/bin/time -v -o "$WORK/time-$label-sampled" "$@" >"$WORK/out-$label" 2>&1 || true
  touch "$WORK/pss-$label.stop"
  wait "$sampler" || true
  for i in $(seq 1 "$runs"); do
    eval "$setup"
    /usr/bin/time -v -o "$WORK/time-$label-$i" "$@" >"$WORK/out-$label" 2>&1 || true
  done
  cp "$WORK/time-$label-$runs" "$WORK/time-$label"
  "$PY" - "$WORK" "$label" "$runs" <<'EOF'
import re, statistics, sys
work, label, runs = sys.argv[1], sys.argv[2], int(sys.argv[3])
def fields(path):
    t = open(path).read()
    def field(name):
        return re.search(re.escape(name) + r":\s*(.+)", t).group(1).strip()
    parts = [float(p) for p in field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")]
    wall = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    return wall, cpu, int(field("Maximum resident set size (kbytes)")) / 1024
timed = [fields(f"{work}/time-{label}-{i}") for i in range(1, runs + 1)]
walls = [w for w, _, _ in timed]
wall, cpu = statistics.median(walls), statistics.median(c for _, c, _ in timed)
rss = fields(f"{work}/time-{label}-sampled")[2]
pss = int(open(f"{work}/pss-{label}").read() or 0) / 1024
print(f"  {label:26s} wall {wall:5.2f} s ({min(walls):.2f}-{max(walls):.2f}, {runs} runs)  cpu {cpu:5.2f} s  "
      f"largest process {rss:4.0f} MB  peak PSS sum {pss:4.0f} MB")
EOF
}

echo
checks="$("$PY" -c 'import json, sys; print(sum(len(l["checks"]) for l in json.load(open(sys.argv[1]))["labs"].values()))' "$ROOT/tools/grade/grading.json")"
echo "1. one full submission (solutions/, every lab, $checks checks)"
# Each submission's render workers use a private shader cache that starts as a
# copy of the seed in $XDG_CACHE_HOME/kit-grade/ (written by --check-references):
# cold is no seed, warm is the seed of the solutions.
# Cold empties the whole cache before each run: no seed, and no decoded references but
# those the build prepared (BUILD_DIR/grade-references, tools/grade.cmake), as in a
# first run after ./kit setup. "unprepared" reads none from there either.
export XDG_CACHE_HOME="$WORK/cache"
for jobs in 1 2; do
  measure "cold-cache-jobs$jobs" 3 'rm -rf "$XDG_CACHE_HOME"' "$GRADE" "$ROOT/solutions" --out "$WORK/one-cold-$jobs" --jobs "$jobs"
done
KIT_PREPARED_REFERENCES="" measure "cold-unprepared-jobs2" 3 'rm -rf "$XDG_CACHE_HOME"' \
  "$GRADE" "$ROOT/solutions" --out "$WORK/one-unprepared-2" --jobs 2
rm -rf "$XDG_CACHE_HOME"
"$GRADE" --check-references >/dev/null
for jobs in 1 2; do
  measure "warm-cache-jobs$jobs" 5 '' "$GRADE" "$ROOT/solutions" --out "$WORK/one-warm-$jobs" --jobs "$jobs"
done

echo
echo "2. batch: 20 submissions (10 solutions, 10 starters), --jobs 2, warm cache"
mkdir -p "$WORK/batch"
for i in $(seq -w 1 10); do
  cp -r "$ROOT/solutions" "$WORK/batch/solution-$i"
  cp -r "$ROOT/labs" "$WORK/batch/starter-$i"
done
measure "batch-20-jobs2" 1 'rm -rf "$WORK/batch-out"' "$GRADE" --batch "$WORK/batch" --out "$WORK/batch-out" --jobs 2
"$PY" - "$WORK/time-batch-20-jobs2" <<'EOF'
import re, sys
t = open(sys.argv[1]).read()
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\):\s*(\S+)", t).group(1)
parts = [float(p) for p in wall.split(":")]
seconds = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
print(f"  throughput: {20 / seconds * 60:.1f} submissions per minute ({seconds / 20:.2f} s each)")
EOF

echo
echo "3. where the time goes"
mkdir -p "$WORK/empty"
measure "parent-only-empty-folder" 3 '' "$GRADE" "$WORK/empty" --out "$WORK/empty-out" --jobs 1
"$PY" - "$WORK/one-warm-1/summary.json" "$WORK/time-warm-cache-jobs1" "$WORK/one-cold-1/summary.json" "$WORK/time-cold-cache-jobs1" <<'EOF'
import json, re, sys
def total_cpu(time_file):
    t = open(time_file).read()
    return sum(float(re.search(name + r":\s*(\S+)", t).group(1)) for name in ("User time \\(seconds\\)", "System time \\(seconds\\)"))
args = sys.argv[1:]
for (path, time_file), label in zip(zip(args[0::2], args[1::2]), ["warm cache, --jobs 1", "cold cache, --jobs 1"]):
    s = json.load(open(path))
    children = sum(lab["seconds"]["child_cpu"] for lab in s["labs"].values())
    cpu = total_cpu(time_file)
    # The grading process's own CPU (start-up, references, comparisons, report): all of
    # kit-grade's CPU less its labs' (summary.json; a worker's exit after its last lab
    # counts here).
    print(f"  {label}: execution {s['execution_time']:.2f} s; CPU {cpu:.2f} s: grading process {cpu - children:.2f} s, "
          f"render workers {children:.2f} s")
    print("    lab  child wall  cpu    context compile render readback | compare  rss MB  vm peak MB")
    for n, lab in sorted(s["labs"].items()):
        t, sec = lab["child_timings"], lab["seconds"]
        print(f"    {n:3s}  {sec['child_wall']:9.3f}  {sec['child_cpu']:5.3f}  {t.get('context', 0):7.3f} {t.get('compile', 0):7.3f}"
              f" {t.get('render', 0):6.3f} {t.get('readback', 0):8.3f} | {sec['compare']:7.3f}  {lab['child_max_rss_kib'] / 1024:6.0f}"
              f"  {lab['child_vm_peak_kib'] / 1024:10.0f}")
EOF

# per_scene LABEL SETUP: one more run at --jobs 1 (SETUP as for measure), its render
# children's files kept, read and removed.
per_scene() {
  local label="$1" setup="$2" kept
  eval "$setup"
  kept="$("$GRADE" "$ROOT/solutions" --out "$WORK/scenes-out" --jobs 1 --keep-temp 2>&1 >/dev/null |
    sed -n 's/^kit-grade: temporary files kept in //p')"
  [ -d "$kept" ] || { echo "measure: no kept folder for the $label run" >&2; return 1; }
  "$PY" - "$label" "$kept" <<'EOF'
import glob, json, os, sys
label, kept = sys.argv[1], sys.argv[2]
print(f"  {label}, --jobs 1, per scene: seconds in the child for its setup, then its frames")
print("    lab  scene                                setup  frames   draw")
for path in sorted(glob.glob(os.path.join(kept, "submission-*", "lab*", "child.json"))):
    child = json.load(open(path))
    lab = os.path.basename(os.path.dirname(path))[3:]
    draws = {}
    for render, seconds in child["seconds"].get("render_each", {}).items():
        name = child.get("renderer_of", {}).get(render, "?")
        n, total = draws.get(name, (0, 0.0))
        draws[name] = (n + 1, total + seconds)
    for name, setup in child["seconds"].get("compile_each", {}).items():
        n, total = draws.get(name, (0, 0.0))
        print(f"    {lab:3s}  {name:35s}  {setup:5.3f}  {n:6d}  {total:5.3f}")
EOF
  rm -rf "$kept" "$WORK/scenes-out"
}
per_scene "warm cache" ''   # the seed section 1 wrote: no run since writes it
per_scene "cold cache" 'rm -rf "$XDG_CACHE_HOME"'
