#!/usr/bin/env bash
# instructor/distros/devcontainer_check.sh [--student-copy N] [BASE_TAR] [DIR]: the dev container's steps
# (.devcontainer/) where Docker cannot run, in a fresh Debian 12 chroot, timed one by one:
#   image       what the Dockerfile runs: the kit script and .devcontainer/install.sh copied
#               alone to /tmp/kit-image, install.sh as root (the packages of ./kit packages,
#               the user vscode), the copy removed;
#   postcreate  devcontainer.json's postCreateCommand (./kit setup, after an apt-get update:
#               the desktop-lite feature, installed over the image, deletes the apt lists, as
#               this script does before the step), as vscode in the kit at /workspaces/kit, with
#               the container's environment (containerEnv);
#   demo        ./kit demo there;
#   vnc         the ctest's check, tests/devcontainer_test.py: the viewer on a TigerVNC
#               display, screenshot through VNC.
# DIR (default /var/tmp/dc-chroot) is made afresh with fresh_debian.sh (Debian 12 minbase,
# ca-certificates), which also mounts /proc, /sys and /dev for each step. The kit copied in
# is this working tree's files (git's tracked and untracked-but-not-ignored, as ./kit
# student-copy takes them), or with --student-copy N the copy ./kit student-copy N writes (a
# student's container: its ./kit setup installs nothing more). A measurement, not a ctest:
# it downloads the packages. Run as root. Logs: DIR.logs/.
# Exit status: 0 when every step passed, 1 when one failed, 2 on a set-up error.
set -uo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
lab=""
if [ "${1:-}" = "--student-copy" ]; then lab="${2:?--student-copy needs a lab number}"; shift 2; fi
dir="${1:-/var/tmp/dc-chroot}"
logs="$dir.logs"
die() { printf 'devcontainer_check.sh: %s\n' "$*" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || die "run as root: chroot and bind mounts need it"
chroot_run() { "$ROOT/instructor/distros/fresh_debian.sh" "$dir" -- "$@"; }

start=$SECONDS
rm -rf "$dir" "$logs" && mkdir -p "$logs" || die "cannot create $logs"
chroot_run true || die "cannot make a Debian 12 chroot at $dir"
if [ -n "$lab" ]; then
  "$ROOT/kit" student-copy "$lab" "$dir/workspaces/kit" >"$logs/student-copy.log" 2>&1 ||
    die "./kit student-copy $lab failed (see $logs/student-copy.log)"
  what="a student copy for lab $lab"
else
  mkdir -p "$dir/workspaces/kit"
  (cd "$ROOT" && git ls-files -z --cached --others --exclude-standard | xargs -0 -r ls -d 2>/dev/null |
    tar -cf - -T -) | tar -xf - -C "$dir/workspaces/kit" || die "cannot copy the kit into $dir"
  what="the kit's working tree"
fi
printf '%-11s %s\n' chroot "$(. "$dir/etc/os-release"; echo "$PRETTY_NAME") at $dir, $what in /workspaces/kit, $((SECONDS - start)) s"

failed=0
env_args=()  # the container's environment (devcontainer.json's containerEnv), once read
# step NAME USER COMMAND: runs COMMAND with bash in the chroot as USER, logs it, one line.
step() {
  local name="$1" user="$2" command="$3" t0=$SECONDS status
  chroot_run env -i HOME="$([ "$user" = root ] && echo /root || echo "/home/$user")" USER="$user" \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 TERM=dumb \
    "${env_args[@]}" runuser -u "$user" -- bash -c "$command" >"$logs/$name.log" 2>&1
  status=$?
  printf '%-11s %s %5d s  %s\n' "$name" "$([ $status = 0 ] && echo ok || echo FAILED)" $((SECONDS - t0)) \
    "$(grep -v '^\s*$' "$logs/$name.log" | tail -n1)"
  [ $status = 0 ] || { failed=1; echo "            (exit $status; $logs/$name.log)"; }
  return $status
}

# The Dockerfile's COPY and RUN.
mkdir -p "$dir/tmp/kit-image" && cp "$dir/workspaces/kit/kit" "$dir/workspaces/kit/.devcontainer/install.sh" "$dir/tmp/kit-image/"
step image root "bash /tmp/kit-image/install.sh && rm -rf /tmp/kit-image" || exit 1
printf '%-11s %s on disk\n' "" "$(du -shx "$dir" | cut -f1)"
# What desktop-lite's installation leaves: no apt lists.
rm -rf "$dir"/var/lib/apt/lists/*
dc="$dir/workspaces/kit/.devcontainer/devcontainer.json"
post="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["postCreateCommand"])' "$dc")" ||
  die "no postCreateCommand in $dc"
env_args=()
mapfile -t env_args < <(python3 -c 'import json, sys
for k, v in json.load(open(sys.argv[1])).get("containerEnv", {}).items(): print(f"{k}={v}")' "$dc")
# The workspace belongs to the container's user (a bind mount, its uid mapped to vscode's).
chown -R 1000:1000 "$dir/workspaces/kit"
step postcreate vscode "cd /workspaces/kit && $post" || exit 1
step demo vscode "cd /workspaces/kit && ./kit demo"
step vnc vscode "cd /workspaces/kit && KIT_SCENE_DIR=build/default/scenes python3 tests/devcontainer_test.py \
  build/default/tools/kit-view build/default/tools/kit-render /tmp/devcontainer-test"
printf '%-11s %d s in all\n' total $((SECONDS - start))
exit $failed
