#!/usr/bin/env bash
# Runs .ci/run from a fresh clone inside a brand-new Debian 12 root (debootstrap
# minbase + git, nothing else), so that every package CI needs must be installed
# by our own scripts (issue 25: clang's OpenMP runtime was on our machines only
# because somebody had installed it by hand).
#   scripts/fresh-root-ci.sh [ROOT_DIR] [COMMIT]
# ROOT_DIR defaults to /tmp/jsatlas-fresh-root (deleted and made anew); COMMIT to
# HEAD. Needs root (chroot, mount) and Debian's mirror; installs debootstrap on
# the host if missing. Prints the wall time of .ci/run inside the root.
set -euo pipefail
cd "$(dirname "$0")/.."
root="${1:-/tmp/jsatlas-fresh-root}"
commit="${2:-$(git rev-parse HEAD)}"
[ "$(id -u)" -eq 0 ] || { echo "fresh-root-ci: needs root (chroot)" >&2; exit 2; }
command -v debootstrap > /dev/null || {
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap
}
cleanup() {
  for m in proc sys dev/pts dev; do umount -l "$root/$m" 2> /dev/null || true; done
}
trap cleanup EXIT
cleanup
rm -rf "$root"
echo "fresh-root-ci: debootstrap bookworm (minbase + git, ca-certificates) into $root"
debootstrap --variant=minbase --include=git,ca-certificates bookworm "$root" \
  http://deb.debian.org/debian > "$root.debootstrap.log" 2>&1 || {
  tail -n 30 "$root.debootstrap.log"; exit 1; }
mount -t proc proc "$root/proc"
mount --rbind /sys "$root/sys"
mount --rbind /dev "$root/dev"
cp /etc/resolv.conf "$root/etc/resolv.conf"
# A fresh clone of the commit under test: a bare copy of this repository's
# objects, then a clone of it, so nothing untracked and no build tree comes along.
git clone --quiet --no-local . "$root/src.git" --bare
chroot "$root" git clone --quiet /src.git /jsatlas
chroot "$root" git -C /jsatlas checkout --quiet "$commit"
start=$SECONDS
chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root \
  bash -c 'cd /jsatlas && .ci/run' 2>&1 | tee "$root.ci.log"
rc=${PIPESTATUS[0]}
echo "fresh-root-ci: .ci/run exited $rc after $((SECONDS - start)) s (log: $root.ci.log)"
exit "$rc"
