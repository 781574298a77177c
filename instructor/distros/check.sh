#!/usr/bin/env bash
# instructor/distros/check.sh SUITE [options]: tries the kit on another distribution, as a
# new user would there, in a fresh chroot: makes it with debootstrap, clones this kit's
# committed HEAD into it, runs ./kit setup, ./kit demo, ./kit test and grades the reference
# solutions with the shipped references (also under softpipe). One line per step; each
# step's whole output is in DIR/logs/. Run as root (debootstrap, chroot, mounts).
#
#   instructor/distros/check.sh trixie                 # Debian 13
#   instructor/distros/check.sh bookworm --steps setup,grade
#   instructor/distros/check.sh noble --mirror URL     # Ubuntu 24.04, from an Ubuntu mirror
#
# Options:
#   --dir DIR        where the chroot goes (default /var/tmp/kit-distros/SUITE); an existing
#                    chroot there is reused (debootstrap is skipped), its clone replaced
#   --mirror URL     the archive debootstrap reads (default: this machine's Debian archive
#                    from its apt sources, else http://deb.debian.org/debian)
#   --steps LIST     comma-separated, of: setup, demo, test, grade, grade-softpipe (default all)
#   --keep-mounts    leave /proc, /sys, /dev and /dev/pts bound into the chroot at the end
# Exit status: 0 when every step passed, 1 when one failed, 2 on a usage or set-up error.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
say() { printf '%s\n' "$*"; }
die() { printf 'check.sh: %s\n' "$*" >&2; exit 2; }

suite="" dir="" mirror="" steps="setup,demo,test,grade,grade-softpipe" keep_mounts=0
while [ $# -gt 0 ]; do
  case "$1" in
    --dir) dir="${2:?--dir needs a folder}"; shift 2 ;;
    --mirror) mirror="${2:?--mirror needs a URL}"; shift 2 ;;
    --steps) steps="${2:?--steps needs a list}"; shift 2 ;;
    --keep-mounts) keep_mounts=1; shift ;;
    -h|--help) sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown option '$1'" ;;
    *) [ -z "$suite" ] || die "one SUITE only (got '$suite' and '$1')"; suite="$1"; shift ;;
  esac
done
[ -n "$suite" ] || die "usage: check.sh SUITE [--dir DIR] [--mirror URL] [--steps LIST] (e.g. trixie)"
[ "$(id -u)" -eq 0 ] || die "run as root: debootstrap, chroot and bind mounts need it"
dir="${dir:-/var/tmp/kit-distros/$suite}"
logs="$dir.logs"

# The archive this machine's apt already uses (deb822 .sources or one-line sources.list).
default_mirror() {
  local uri
  uri="$(grep -hE '^(URIs:|deb )' /etc/apt/sources.list.d/*.sources /etc/apt/sources.list 2>/dev/null |
         grep -v security | sed -E 's/^URIs:[[:space:]]*//; s/^deb (\[[^]]*\] )?//; s/[[:space:]].*$//' | head -n1)"
  echo "${uri:-http://deb.debian.org/debian}"
}
mirror="${mirror:-$(default_mirror)}"

mounted=()
unmount_all() {
  [ "$keep_mounts" = 1 ] && return
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[$i]}" 2>/dev/null; done
}
trap unmount_all EXIT

# in_chroot COMMAND: runs COMMAND with bash in the clone, with a clean environment, and
# this machine's extra certificate authorities where it has some (host_ca, below).
in_chroot() {
  chroot "$dir" env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 TERM=dumb DEBIAN_FRONTEND=noninteractive ${host_ca:+NODE_EXTRA_CA_CERTS=$host_ca} \
    bash -c "cd /root/kit && $1"
}
host_ca=""

failed=0
# step NAME COMMAND [SUMMARY]: runs COMMAND in the chroot, logs it, prints one line; SUMMARY
# (run here, with bash) adds its last line of output to it.
step() {
  local name="$1" command="$2" summary="${3:-}" start=$SECONDS status line
  in_chroot "$command" >"$logs/$name.log" 2>&1
  status=$?
  line="$(printf '%-15s %s  %4d s' "$name" "$([ $status = 0 ] && echo ok || echo FAILED)" $((SECONDS - start)))"
  if [ -n "$summary" ]; then line="$line  $(eval "$summary" 2>/dev/null | tail -n1)"; fi
  [ $status = 0 ] || { line="$line  (exit $status; $logs/$name.log)"; failed=1; }
  say "$line"
}

mkdir -p "$logs" || die "cannot create $logs"
start=$SECONDS
if [ ! -x "$dir/bin/bash" ]; then
  command -v debootstrap >/dev/null || apt-get install -y -qq debootstrap >/dev/null ||
    die "debootstrap is missing and could not be installed"
  debootstrap --variant=minbase "$suite" "$dir" "$mirror" >"$logs/debootstrap.log" 2>&1 ||
    die "debootstrap $suite $dir $mirror failed (see $logs/debootstrap.log)"
fi
# /sys recursively, as fresh_debian.sh binds it: its cgroup file system is a mount of its own,
# and through it the kit sees a memory limit the chroot runs under (kit's build_memory_mib),
# as it does in a container.
for m in proc sys dev dev/pts; do
  bind=--bind
  [ "$m" = sys ] && bind=--rbind
  mountpoint -q "$dir/$m" || { mount "$bind" "/$m" "$dir/$m" && mounted+=("$dir/$m"); } ||
    die "cannot bind /$m into $dir"
done
cp /etc/resolv.conf "$dir/etc/resolv.conf" 2>/dev/null
# A network whose TLS is inspected (a proxy's own authority, which this machine trusts through
# NODE_EXTRA_CA_CERTS) reaches npm's registry from the chroot only with that authority too:
# ./kit test's browser build runs npm ci. Without it npm stops at SELF_SIGNED_CERT_IN_CHAIN.
if [ -n "${NODE_EXTRA_CA_CERTS:-}" ] && [ -f "$NODE_EXTRA_CA_CERTS" ]; then
  cp "$NODE_EXTRA_CA_CERTS" "$dir/etc/kit-host-ca.crt" && host_ca=/etc/kit-host-ca.crt
fi
in_chroot_root() { chroot "$dir" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive bash -c "$1"; }
in_chroot_root "command -v git >/dev/null || { apt-get update -qq && apt-get install -y -qq --no-install-recommends git ca-certificates; }" \
  >"$logs/git.log" 2>&1 || die "cannot install git in the chroot (see $logs/git.log)"
rm -rf "$dir/root/kit"
git clone -q --no-hardlinks "$ROOT" "$dir/root/kit" || die "cannot clone $ROOT into the chroot"
say "$(printf '%-15s %s' chroot "$suite at $dir ($(in_chroot_root '. /etc/os-release; echo "$PRETTY_NAME"')), kit $(git -C "$ROOT" rev-parse --short HEAD), $((SECONDS - start)) s")"

# kit-grade prints "total: X/Y" last; ctest "N% tests passed, M tests failed out of K".
grade="./kit grade solutions --out out/distro-grade"
for s in ${steps//,/ }; do
  case "$s" in
    setup) step setup "./kit setup" \
      "in_chroot 'build/default/tools/kit-render --solution --stage 1 --size 8x8 --out /tmp/kit-probe.png --timings 2>&1' | grep -o '([a-z]*: .*)' | head -n1" ;;
    demo) step demo "./kit demo" "grep -o 'demo: .*' '$logs/demo.log'" ;;
    test) step test "./kit test" "grep -E 'tests passed' '$logs/test.log'" ;;
    grade) step grade "$grade" "grep -h '^total:' '$logs/grade.log'" ;;
    # softpipe takes over a minute of CPU for lab 6's maps: a larger --cpu-limit than grading's 30 s.
    grade-softpipe) step grade-softpipe "GALLIUM_DRIVER=softpipe $grade-softpipe --cpu-limit 900 --timeout 1800" "grep -h '^total:' '$logs/grade-softpipe.log'" ;;
    *) die "unknown step '$s' (setup, demo, test, grade, grade-softpipe)" ;;
  esac
done
exit $failed
