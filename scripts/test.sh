#!/usr/bin/env bash
# Builds and runs every default test three times: the normal build, under ASan+UBSan, and
# with the LTTng tracepoints compiled out (the same suite minus the LTTng-only tests).
# Opt-in labels (soak) are excluded; run them with: ctest --test-dir build -L soak
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)

run_suite() {
  local build_dir=$1; shift
  echo "== building $build_dir"
  bash "$root/scripts/build.sh" "$build_dir" "$@"
  echo "== testing $build_dir"
  ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE soak
}

run_suite "$root/build"
bash "$root/scripts/tidy.sh" "$root/build"
run_suite "$root/build-asan" -DHILTWIN_SANITIZE=ON -DHILTWIN_BUILD_BENCH=OFF
run_suite "$root/build-notrace" -DHILTWIN_WITH_LTTNG=OFF -DHILTWIN_BUILD_BENCH=OFF
