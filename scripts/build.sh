#!/usr/bin/env bash
# Configures and builds hiltwin into build/ (or BUILD_DIR), warnings as errors.
# Usage: scripts/build.sh [--run] [BUILD_DIR] [extra cmake -D options...]
#   --run  only what `hiltwin run` needs: the binary and its libraries, not the tests, the
#          benchmarks, the gateware or the Verilator model (so not `--io verilated`); a later
#          full build of the same folder adds them
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
run_only=0
if [[ ${1:-} == --run ]]; then
  run_only=1
  shift
elif [[ ${1:-} == -h || ${1:-} == --help ]]; then
  sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'
  exit 0
fi
build_dir=${1:-"$root/build"}
shift || true
jobs=$(nproc)
# The co-simulation is on unless --run or the caller's own -D says otherwise (a later -D wins).
fpga_sim=ON
((run_only)) && fpga_sim=OFF
# RelWithDebInfo with line tables only (-g1), not full debug information: enough for every
# backtrace, sanitizer report and profiler (perf, callgrind) to name file and line, and full
# debug information is a fifth of what compiling costs (two units of the libraries: 39.5 ->
# 30.7 CPU-s; docs/testing.md). To inspect locals in a debugger: -DCMAKE_BUILD_TYPE=Debug.
line_tables=(-DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
             -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${line_tables[@]}" \
  -DHILTWIN_WERROR=ON -DHILTWIN_FPGA_SIM=$fpga_sim "$@" >/dev/null
if ((run_only)); then
  cmake --build "$build_dir" -j "$jobs" --target hiltwin
else
  cmake --build "$build_dir" -j "$jobs"
fi
