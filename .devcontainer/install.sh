#!/usr/bin/env bash
# The dev container image's set-up, as root, beside a copy of the kit's front door script:
#   install.sh            (the Dockerfile runs it; the same steps work in a Debian 12 chroot)
# 1. the container's own needs (not the kit's): sudo, git, CA certificates;
# 2. the kit's packages, from its one list: ./kit packages;
# 3. the user the editor and the desktop run as (vscode, uid 1000), sudo without a password,
#    so that a later ./kit setup can install what a newer kit adds.
# (The desktop-lite feature, installed over the image, deletes the apt lists; the kit asks
# apt-cache which optional packages the distribution has, so postCreateCommand updates them.)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
user="${KIT_CONTAINER_USER:-vscode}"
export DEBIAN_FRONTEND=noninteractive

apt-get update -qq
apt-get install -y -qq --no-install-recommends sudo git ca-certificates >/dev/null
# After the update: the list asks apt which optional packages this distribution has.
"$here/kit" packages | xargs apt-get install -y -qq --no-install-recommends >/dev/null
echo "install.sh: installed the $("$here/kit" packages | wc -l) packages of ./kit packages"

if ! id "$user" >/dev/null 2>&1; then
  useradd --create-home --shell /bin/bash --uid 1000 "$user"
fi
echo "$user ALL=(root) NOPASSWD:ALL" >"/etc/sudoers.d/$user"
chmod 0440 "/etc/sudoers.d/$user"
apt-get clean
