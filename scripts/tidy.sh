#!/usr/bin/env bash
# Enforces the function-size rule of .clang-tidy (readability-function-size, 80 lines: a
# function fits on a screen) on every first-party source, with the compile commands of a build.
# The other checks of .clang-tidy are advisory: run `clang-tidy -p build FILE` for them.
# Usage: scripts/tidy.sh [BUILD_DIR]   (BUILD_DIR holds compile_commands.json; default build/)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${1:-"$root/build"}
command -v clang-tidy >/dev/null || {
  echo "tidy: clang-tidy is missing: apt-get install clang-tidy (scripts/setup.sh installs it)" >&2
  exit 1
}
[[ -f "$build_dir/compile_commands.json" ]] || {
  echo "tidy: no $build_dir/compile_commands.json: build first (bash scripts/build.sh)" >&2
  exit 1
}
cd "$root"
# plants/<name>/ holds 20-sim generated code (not ours: a big model's CalculateDynamic is long
# by nature) and msd20sim's hand-written copy of that style, so only plants/ itself is checked.
# fpga_sim/ is ours; the C++ Verilator generates from fpga/rtl lives in the build folder, not here.
mapfile -t files < <(find kernel_glue scheduler qos statemachine io fpga_sim tracing runtime plant fmi \
                          plants telemetry analysis trace_capture app_relbot tests bench \
                          -name '*.cpp' -not -path 'plants/*/*' 2>/dev/null | sort)
echo "== tidy: function size (at most 80 lines) in ${#files[@]} files"
findings=$(printf '%s\n' "${files[@]}" |
           xargs -P "$(nproc)" -n 6 clang-tidy -p "$build_dir" --quiet \
             --checks='-*,readability-function-size' 2>/dev/null | grep -E 'warning:' || true)
if [[ -n "$findings" ]]; then
  echo "$findings"
  echo "tidy: $(wc -l <<<"$findings") functions longer than 80 lines: split each into named steps" >&2
  exit 1
fi
echo "tidy: every function fits in 80 lines"
