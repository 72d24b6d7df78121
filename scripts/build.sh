#!/usr/bin/env bash
# Configures and builds hiltwin into build/ (or $1), warnings as errors.
# Usage: scripts/build.sh [BUILD_DIR] [extra cmake -D options...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${1:-"$root/build"}
shift || true
jobs=$(nproc)
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHILTWIN_WERROR=ON "$@" >/dev/null
cmake --build "$build_dir" -j "$jobs"
