#!/usr/bin/env bash
# instructor/distros/fresh_debian.sh DIR [--suite SUITE] [--copy SRC:DEST]... -- COMMAND [ARG ...]
#
# Runs COMMAND as root inside DIR, a Debian chroot made fresh with debootstrap (minbase,
# ca-certificates) when DIR does not exist yet: the stand-in here for a platform's clean
# image (Gradescope's, PrairieLearn's, a Classroom 50 runner, the dev container), which
# cannot be built with Docker on these machines. /proc, /sys, /dev and the host's DNS
# are mounted for the command and unmounted after it. --copy copies a file or folder of
# the host into the chroot first (DEST is inside DIR). The first debootstrap of a suite
# is kept as /var/tmp/kit-debian-SUITE.tar, so later fresh chroots take seconds.
# A measurement tool (it downloads packages), not a test: instructor/platforms.md lists
# the runs made with it. Needs root and debootstrap (apt-get install debootstrap).
set -euo pipefail

[ $# -ge 1 ] || { echo "usage: $0 DIR [--suite SUITE] [--copy SRC:DEST]... -- COMMAND [ARG ...]" >&2; exit 2; }
dir="$1"; shift
suite=bookworm
copies=()
while [ $# -gt 0 ]; do
  case "$1" in
    --suite) suite="$2"; shift 2 ;;
    --copy) copies+=("$2"); shift 2 ;;
    --) shift; break ;;
    *) echo "fresh_debian: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ $# -gt 0 ] || { echo "fresh_debian: no COMMAND after --" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "fresh_debian: needs root" >&2; exit 2; }

if [ ! -d "$dir" ]; then
  cache="/var/tmp/kit-debian-$suite.tar"
  if [ ! -f "$cache" ]; then
    command -v debootstrap >/dev/null || { echo "fresh_debian: install debootstrap" >&2; exit 2; }
    debootstrap --variant=minbase --include=ca-certificates "$suite" "$cache.d" http://deb.debian.org/debian >&2
    tar -C "$cache.d" -cf "$cache" . && rm -rf "$cache.d"
  fi
  mkdir -p "$dir" && tar -C "$dir" -xf "$cache"
fi
for copy in "${copies[@]}"; do
  mkdir -p "$dir/$(dirname "${copy#*:}")"
  cp -a "${copy%%:*}" "$dir/${copy#*:}"
done

mounted=()
cleanup() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
for m in proc sys dev dev/pts; do
  mkdir -p "$dir/$m"
  case "$m" in
    proc) mount -t proc proc "$dir/proc" ;;
    *) mount --rbind "/$m" "$dir/$m" ;;
  esac
  mounted+=("$dir/$m")
done
cp /etc/resolv.conf "$dir/etc/resolv.conf"
chroot "$dir" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 "$@"
