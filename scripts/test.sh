#!/usr/bin/env bash
# Builds and runs every default test three times: the normal build, under ASan+UBSan, and
# with the LTTng tracepoints compiled out (the same suite minus the LTTng-only tests).
# Opt-in labels are excluded: soak, and rtl_long (the RTL co-simulation's minutes-long runs,
# docs/fpga-cosim.md); run them with: ctest --test-dir build -L soak (or -L rtl_long)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)

run_suite() {
  local build_dir=$1; shift
  echo "== building $build_dir"
  bash "$root/scripts/build.sh" "$build_dir" "$@"
  echo "== testing $build_dir"
  ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE "soak|rtl_long"
}

run_suite "$root/build"
bash "$root/scripts/tidy.sh" "$root/build"
run_suite "$root/build-asan" -DHILTWIN_SANITIZE=ON -DHILTWIN_BUILD_BENCH=OFF
run_suite "$root/build-notrace" -DHILTWIN_WITH_LTTNG=OFF -DHILTWIN_BUILD_BENCH=OFF
