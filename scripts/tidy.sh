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
# models/plants/<name>/ holds 20-sim generated code (not ours: a big model's CalculateDynamic is
# long by nature) and msd20sim's hand-written copy of that style, so only models/plants/ itself
# is checked. board/fpga_sim/ is ours; the C++ Verilator generates from board/fpga/rtl lives in
# the build folder, not here. examples/ build only against an installed hiltwin (the install
# test), so no compile command here describes them.
tiers=(engine board models relbot observe cli tests bench)
mapfile -t files < <(find "${tiers[@]}" -name '*.cpp' -not -path 'models/plants/*/*' 2>/dev/null \
                       | sort)
declare -A wanted covered
for f in "${files[@]}"; do wanted[$f]=1; done
# Unity builds (cmake/HiltwinTargets.cmake) compile most sources inside Unity/unity_*.cxx, and
# those units are what the compile database lists. Each unit is checked once; the header filter
# reports the functions of the sources it includes (and only theirs: the same files as above).
# A listed file that this build does not compile (a module configured out) is checked with the
# flags clang-tidy borrows from its nearest neighbour in the database. The configuration is
# named: a unit in a build folder outside the tree would not find .clang-tidy by itself.
inputs=()
while IFS= read -r unit; do
  if [[ $unit == */Unity/unity_*.cxx ]]; then
    use=0
    while IFS= read -r source; do
      if [[ -n ${wanted[${source#"$root/"}]:-} ]]; then covered[${source#"$root/"}]=1; use=1; fi
    done < <(sed -n 's/^#include "\(.*\)"$/\1/p' "$unit")
    ((use)) && inputs+=("$unit")
  elif [[ -n ${wanted[${unit#"$root/"}]:-} ]]; then
    covered[${unit#"$root/"}]=1
    inputs+=("$unit")
  fi
done < <(grep -o '"file": "[^"]*"' "$build_dir/compile_commands.json" | cut -d'"' -f4 | sort -u)
for f in "${files[@]}"; do [[ -n ${covered[$f]:-} ]] || inputs+=("$root/$f"); done
dirs=$(IFS='|'; echo "${tiers[*]}")
echo "== tidy: function size (at most 80 lines) in ${#files[@]} files (${#inputs[@]} units)"
# The tests compile with a GCC precompiled header (cmake/HiltwinTargets.cmake), which clang
# cannot read. clang-tidy gets clang's own of the same header, made once here with the GCC
# header's compile command (the same flags, so the units that use it match it): without it every
# test unit parses GoogleTest, gmock and nlohmann-json again (the largest unit of the CLI tests:
# 9.2 s with them parsed, 7.4 s with it; the whole check 566 -> 548 CPU-s, docs/testing.md).
work=$(mktemp -d "${TMPDIR:-/tmp}/hiltwin-tidy.XXXXXX")
trap 'rm -rf "$work"' EXIT
pch_command=$(grep -o '"command": "[^"]*-x c++-header[^"]*cmake_pch\.hxx\.cxx"' \
                "$build_dir/compile_commands.json" | head -1 | cut -d'"' -f4)
pch_flags=()  # none without tests: no unit names the GCC header then
if [[ -n $pch_command ]]; then
  header=$(sed -E 's#.* -include ([^ ]*/cmake_pch\.hxx) .*#\1#' <<<"$pch_command")
  to_clang='s#^[^ ]+#clang++#; s# -Winvalid-pch##; s# -include [^ ]*cmake_pch\.hxx##'
  to_clang+="; s# -c [^ ]+\$##; s# -o [^ ]+# -o $work/tests.pch#"
  read -ra clang_pch_command <<<"$(sed -E "$to_clang" <<<"$pch_command")"
  "${clang_pch_command[@]}" -w "$header" 2>"$work/pch.err" || {
    cat "$work/pch.err" >&2
    echo "tidy: clang could not precompile the tests' header $header (above)" >&2
    exit 1
  }
  pch_flags=(-include-pch "$work/tests.pch")
fi
sed -E 's# -Winvalid-pch##g; s# -include [^ "]*/cmake_pch\.hxx# '"${pch_flags[*]}"'#g' \
  "$build_dir/compile_commands.json" >"$work/compile_commands.json"
# -w: the compiler's own warnings are GCC's business (the build has them as errors, and some
# are GCC-only options clang does not know); the check's findings are not compiler warnings.
# The module include folders: a source this build does not compile (the installed-package
# example, a test of a configuration switched off) borrows a neighbour's flags, which may lack
# its module's folder.
extra=(--extra-arg=-w)
for include in "$root"/*/include "$root"/*/*/include; do extra+=(--extra-arg="-I$include"); done
status=0
printf '%s\n' "${inputs[@]}" |
  xargs -P "$(nproc)" -n 2 clang-tidy -p "$work" --quiet --config-file="$root/.clang-tidy" \
    "${extra[@]}" --header-filter="^$root/($dirs)/([^/]+/)*[^/]+\\.cpp\$" \
    --checks='-*,readability-function-size' >"$work/out" 2>"$work/err" || status=$?
# A unit clang cannot parse is not a unit that passed: its errors are shown and the check fails.
if ((status != 0)); then
  grep -E 'error:|Error while processing' "$work/out" "$work/err" | sort -u | head -20 >&2
  echo "tidy: clang-tidy could not check every unit (exit $status): fix the errors above" >&2
  exit 1
fi
findings=$(grep -E 'warning:.*\[readability-function-size\]' "$work/out" | sort -u || true)
if [[ -n "$findings" ]]; then
  echo "$findings"
  echo "tidy: $(wc -l <<<"$findings") functions longer than 80 lines: split each into named steps" >&2
  exit 1
fi
echo "tidy: every function fits in 80 lines"
