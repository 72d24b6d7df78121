#!/usr/bin/env bash
# Builds and runs every default test three times: the normal build, under ASan+UBSan, and
# under ThreadSanitizer with the LTTng tracepoints compiled out (the same suite minus the
# LTTng-only tests: the lock-free queues, the logger and the wire raced for real, and the
# no-LTTng configuration built and tested on the way). Then a bounded, seeded libFuzzer run of
# every parser (scripts/fuzz.sh, under a minute).
# The opt-in label soak is excluded (run it with: ctest --test-dir build -L soak); the gateware's
# tests run in the normal build only (below).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)

run_suite() {
  local build_dir=$1 exclude=$2; shift 2
  echo "== building $build_dir"
  bash "$root/scripts/build.sh" "$build_dir" "$@"
  echo "== testing $build_dir"
  ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE "$exclude"
}

# The gateware is checked once, in the normal build: bitstreams with their 100 MHz timing gate
# and the lint (label fpga), and the RTL co-simulation including its two long runs (label
# rtl_long: the 720,000-message encoder test and the closed loop through both RTL boards, about
# 4 minutes each). The sanitizer build co-simulates too (its own code under ASan) but skips the
# long runs; the ThreadSanitizer (no-LTTng) build leaves the gateware out.
run_suite "$root/build" "soak"
bash "$root/scripts/tidy.sh" "$root/build"
run_suite "$root/build-asan" "soak|rtl_long" -DHILTWIN_SANITIZE=ON -DHILTWIN_BUILD_BENCH=OFF \
  -DHILTWIN_FPGA=OFF
# Under TSan each test stops at its first report (TSAN_OPTIONS set by CTest, with
# tests/tsan.supp for the uninstrumented Debian libraries): a race fails it, not a log line.
run_suite "$root/build-tsan" "soak|rtl_long" -DHILTWIN_TSAN=ON -DHILTWIN_WITH_LTTNG=OFF \
  -DHILTWIN_BUILD_BENCH=OFF -DHILTWIN_FPGA=OFF -DHILTWIN_FPGA_SIM=OFF
bash "$root/scripts/fuzz.sh"
