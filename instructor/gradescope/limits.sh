#!/usr/bin/env bash
# instructor/gradescope/limits.sh [--cpus C] [--memory MIB] -- COMMAND [ARG ...]
#
# Runs COMMAND as Gradescope runs an autograder by default: half a CPU and 768 MB of
# memory, no swap (gradescope/autograder_samples, docs/troubleshooting.md), in a cgroup of
# its own (v2 or v1; root only). Prints the wall time, the cgroup's peak memory and how many
# times the kernel killed a process for memory, then exits with COMMAND's status. A
# measurement, not a test: the figures are in instructor/platforms.md.
#   --cpus C      CPU time a second, in CPUs (default 0.5)
#   --memory MIB  memory limit in MiB (default 768), page cache included, as a container's is
set -euo pipefail

cpus=0.5
memory=768
while [ $# -gt 0 ]; do
  case "$1" in
    --cpus) cpus="$2"; shift 2 ;;
    --memory) memory="$2"; shift 2 ;;
    --) shift; break ;;
    *) break ;;
  esac
done
[ $# -gt 0 ] || { echo "usage: $0 [--cpus C] [--memory MIB] -- COMMAND [ARG ...]" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "limits.sh: needs root to make a cgroup" >&2; exit 2; }

name="kit-limits-$$"
period=100000
quota="$(awk -v c="$cpus" -v p="$period" 'BEGIN { printf "%d", c * p }')"
bytes=$((memory * 1024 * 1024))

if [ -f /sys/fs/cgroup/cgroup.controllers ]; then  # cgroup v2
  group="/sys/fs/cgroup/$name"
  mkdir "$group"
  echo "$quota $period" >"$group/cpu.max"
  echo "$bytes" >"$group/memory.max"
  echo 0 >"$group/memory.swap.max" 2>/dev/null || true
  groups=("$group")
  peak() { cat "$group/memory.peak" 2>/dev/null || echo 0; }
  kills() { awk '$1 == "oom_kill" { print $2 }' "$group/memory.events"; }
else  # cgroup v1: one group in the memory and one in the cpu hierarchy
  mem="/sys/fs/cgroup/memory/$name" cpu="/sys/fs/cgroup/cpu/$name"
  mkdir "$mem" "$cpu"
  echo "$bytes" >"$mem/memory.limit_in_bytes"
  echo "$bytes" >"$mem/memory.memsw.limit_in_bytes" 2>/dev/null || true
  echo "$period" >"$cpu/cpu.cfs_period_us"
  echo "$quota" >"$cpu/cpu.cfs_quota_us"
  groups=("$mem" "$cpu")
  peak() { cat "$mem/memory.max_usage_in_bytes"; }
  kills() { awk '$1 == "oom_kill" { print $2 }' "$mem/memory.oom_control"; }
fi
cleanup() {
  for g in "${groups[@]}"; do
    while read -r pid; do kill -9 "$pid" 2>/dev/null || true; done <"$g/cgroup.procs"
    rmdir "$g" 2>/dev/null || true
  done
}
trap cleanup EXIT

start=$(date +%s.%N)
set +e
# The child joins the groups before it execs COMMAND, so everything it starts is counted.
bash -c 'for g in "$@"; do [ "$g" = -- ] && break; echo $$ >"$g/cgroup.procs"; done
         while [ "$1" != -- ]; do shift; done; shift; exec "$@"' limits "${groups[@]}" -- "$@"
status=$?
set -e
end=$(date +%s.%N)
printf 'limits: %s CPU, %s MiB: wall %.1f s, peak memory %d MiB, %s process(es) killed for memory, exit %d\n' \
  "$cpus" "$memory" "$(awk -v a="$start" -v b="$end" 'BEGIN { print b - a }')" "$(($(peak) / 1024 / 1024))" "$(kills)" "$status" >&2
exit "$status"
