#!/usr/bin/env bash
# Builds and runs every default test four times: the normal build; cross-built for arm64 (the
# Raspberry Pi 4) and run under qemu-aarch64; under ASan+UBSan; and under ThreadSanitizer with
# the LTTng tracepoints compiled out (the same suite minus the LTTng-only tests: the lock-free
# queues, the logger and the wire raced for real, and the no-LTTng configuration built and
# tested on the way). Then a bounded, seeded libFuzzer run of every parser (scripts/fuzz.sh,
# under a minute).
# The opt-in label soak is excluded (run it with: ctest --test-dir build -L soak); the gateware's
# tests run in the normal build only (below).
# Usage: bash scripts/test.sh [--skip-arm64]   (the arm64 stage needs scripts/setup.sh --cross arm64)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)
arm64=1
case ${1:-} in
  "") ;;
  --skip-arm64) arm64=0 ;;
  -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "test: unknown argument '$1' (known: --skip-arm64, --help)" >&2; exit 2 ;;
esac

# The second builds (arm64, the sanitizers) keep line tables only (-g1): enough for every
# sanitizer report and backtrace, and full debug info is much of what compiling costs here.
line_tables=(-DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
             -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")

# Each stage says how long it built and tested: CI has 90 minutes for all of them.
run_suite() {
  local build_dir=$1 exclude=$2; shift 2
  local start=$SECONDS
  echo "== building $build_dir"
  bash "$root/scripts/build.sh" "$build_dir" "$@"
  local built=$SECONDS
  echo "== testing $build_dir"
  ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE "$exclude"
  echo "== $build_dir: built in $((built - start)) s, tested in $((SECONDS - built)) s"
}

# The gateware is checked once, in the normal build: bitstreams with their 100 MHz timing gate
# and the lint (label fpga), and the RTL co-simulation including its two long runs (label
# rtl_long: the 720,000-message encoder test and the closed loop through both RTL boards, about
# 4 minutes each). The sanitizer build co-simulates too (its own code under ASan) but skips the
# long runs; the ThreadSanitizer (no-LTTng) build leaves the gateware out.
run_suite "$root/build" "soak"
bash "$root/scripts/tidy.sh" "$root/build"

# arm64, cross-built with Debian's toolchain against its arm64 libraries (multiarch) and run
# under qemu-aarch64: CTest starts each test through the emulator, and binfmt_misc runs the arm64
# programs a test starts (the hiltwin binary, a peer) under it too. Left out, and listed below:
# the wall-clock tests (label rt: an emulated CPU's timing tells nothing of a Pi's), the tests
# of LTTng and the kernel tracer (the host's session daemon and tracefs, labels lttng and
# tracefs), and the gateware (no FPGA toolchain runs for arm64 here).
if ((arm64)); then
  if [[ ! -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ]]; then
    echo "test: qemu-aarch64 is not registered with binfmt_misc: run bash scripts/setup.sh" \
         "--cross arm64 (as root or with sudo), or skip this stage with --skip-arm64" >&2
    exit 1
  fi
  arm64_left_out="soak|rt|lttng|tracefs"
  run_suite "$root/build-arm64" "$arm64_left_out" \
    --toolchain "$root/cmake/toolchains/aarch64-linux-gnu.cmake" -DHILTWIN_BUILD_BENCH=OFF \
    -DHILTWIN_FPGA=OFF -DHILTWIN_FPGA_SIM=OFF "${line_tables[@]}"
  echo "== arm64: tests not run under qemu (wall clock, LTTng, tracefs; soak is opt-in):"
  ctest --test-dir "$root/build-arm64" -N -L "$arm64_left_out" | grep -E "Test +#|Total"
fi
run_suite "$root/build-asan" "soak|rtl_long" -DHILTWIN_SANITIZE=ON -DHILTWIN_BUILD_BENCH=OFF \
  -DHILTWIN_FPGA=OFF "${line_tables[@]}"
# Under TSan each test stops at its first report (TSAN_OPTIONS set by CTest, with
# tests/tsan.supp for the uninstrumented Debian libraries): a race fails it, not a log line.
# The wall-clock tests (label rt) run after the rest, one at a time: instrumented, a process
# runs several times slower, and two real-time pairs side by side on two cores starve each
# other's SCHED_OTHER threads past the wire's 250 ms heartbeat (measured: 3 of 17 wire tests
# failed to start within 5 parallel repeats; serially none did).
run_suite "$root/build-tsan" "soak|rtl_long|rt" -DHILTWIN_TSAN=ON -DHILTWIN_WITH_LTTNG=OFF \
  -DHILTWIN_BUILD_BENCH=OFF -DHILTWIN_FPGA=OFF -DHILTWIN_FPGA_SIM=OFF "${line_tables[@]}"
tsan_rt_start=$SECONDS
echo "== testing $root/build-tsan: the wall-clock tests (label rt), one at a time"
ctest --test-dir "$root/build-tsan" --output-on-failure -j 1 -L rt -LE "soak|rtl_long"
echo "== $root/build-tsan: wall-clock tests in $((SECONDS - tsan_rt_start)) s"
bash "$root/scripts/fuzz.sh"
