#!/usr/bin/env bash
# What `jsatlas view` and its browser test need, beyond scripts/install-deps.sh:
#   libjs-three  three.js (three.min.js, OrbitControls.js), inlined into every page
#                (also in scripts/install-deps.sh, since `jsatlas view` needs it);
#   chromium     headless browser of test/browser_view_test.cpp (skipped without it).
# Neither is needed to build jsatlas. Called by .ci/run before the tests. Idempotent.
set -euo pipefail
pkgs=(libjs-three chromium)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-view-deps: all ${#pkgs[@]} packages present"
  exit 0
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "install-view-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
