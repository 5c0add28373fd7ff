#!/usr/bin/env bash
# Fails when a tracked C++ file (*.h, *.cpp) differs from what clang-format
# makes of it with the checked-in .clang-format (Debian 12: clang-format 14).
# Installs the clang-format package if it is missing. Fix drift with
#   git ls-files '*.h' '*.cpp' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-format > /dev/null; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "check-format: installing clang-format"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq clang-format
fi
mapfile -t files < <(git ls-files '*.h' '*.cpp')
clang-format --dry-run --Werror "${files[@]}"
echo "check-format: ${#files[@]} files match .clang-format ($(clang-format --version))"
