#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang only) and runs each on a copy of its seed corpus
# fuzz/corpus/<target>/, one per core at a time, with a fixed seed: by default 10 s each, under
# a minute for all on two cores. Fails when any target finds a crash, a leak, undefined
# behaviour, a timeout or an undocumented exception; the input that did it is kept and its path
# printed.
# The repository's corpus is never written to: new inputs go to a temporary copy.
#
# Usage: scripts/fuzz.sh [--long SECONDS] [--build-dir DIR] [--keep DIR] [--build-only] [TARGET...]
#   --long SECONDS  run each target this long instead (local hunting; e.g. --long 600)
#   --build-only    build the targets and stop (scripts/test.sh --prebuild builds them early)
#   --build-dir DIR the clang build folder (default build-fuzz)
#   --keep DIR      keep each target's grown corpus in DIR/<target> (to pick new seeds from)
#   TARGET          spi_frame wire_layout csv_profile csv_log toml_config cli
#                   fmu_model_description fmu_archive (default: all)
# docs/fuzzing.md says what each target covers and how to turn a finding into a regression case.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
all_targets=(spi_frame wire_layout csv_profile csv_log toml_config cli fmu_model_description
             fmu_archive)
seconds=10
build_dir="$root/build-fuzz"
keep_dir=""
build_only=0
targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --long) seconds=${2:?--long needs a number of seconds per target}; shift 2 ;;
    --build-dir) build_dir=${2:?--build-dir needs a folder}; shift 2 ;;
    --keep) keep_dir=${2:?--keep needs a folder}; shift 2 ;;
    --build-only) build_only=1; shift ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1 (see scripts/fuzz.sh --help)" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[[ ${#targets[@]} -gt 0 ]] || targets=("${all_targets[@]}")
for target in "${targets[@]}"; do
  if [[ ! -d "$root/fuzz/corpus/$target" ]]; then
    echo "fuzz.sh: no target '$target' (choose from: ${all_targets[*]})" >&2
    exit 2
  fi
done
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found; on Debian 12: apt-get install clang libclang-rt-14-dev" >&2
  exit 2
fi

echo "== building the fuzz targets in $build_dir (clang, ASan + UBSan + libFuzzer)"
# Line tables only (-g1): enough for every report's stack. Unoptimised (-O0), not at the -O1
# libFuzzer's documentation suggests for speed: the tree links nearly every library (the
# command-line target links the commands), and -O0 compiles it in 307 instead of 507 CPU-s
# (measured, no compiler cache). A target then runs 2.4 (spi_frame) to 5 (cli) times fewer
# inputs per second, which the default 10 s per target, two targets at a time, partly makes up
# (docs/fuzzing.md).
CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O0 -g1 -DNDEBUG" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O0 -g1 -DNDEBUG" \
  -DHILTWIN_WERROR=ON -DHILTWIN_FUZZ=ON -DHILTWIN_BUILD_TESTS=OFF -DHILTWIN_BUILD_BENCH=OFF \
  -DHILTWIN_FPGA=OFF -DHILTWIN_FPGA_SIM=OFF -DHILTWIN_WITH_LTTNG=OFF >/dev/null
cmake --build "$build_dir" --target hiltwin_fuzzers -j "$(nproc)"
((build_only)) && exit 0

work=$(mktemp -d "${TMPDIR:-/tmp}/hiltwin-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/findings"
findings="$build_dir/fuzz-findings"  # kept after the run, outside the source tree
# run_target TARGET: fuzzes one target on a copy of its corpus; leaves $work/TARGET.log and
# $work/TARGET.result (ok or FINDING). Each target has its own corpus, log, findings prefix and
# scratch folder, so targets run side by side without sharing a file.
run_target() {
  local target=$1 corpus="$work/corpus-$1" result=ok
  cp -r "$root/fuzz/corpus/$target" "$corpus"
  local flags=(-seed=1 -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048
               -print_final_stats=1 -artifact_prefix="$work/findings/$target-")
  if [[ -f "$root/fuzz/dict/$target.dict" ]]; then flags+=(-dict="$root/fuzz/dict/$target.dict"); fi
  mkdir -p "$work/tmp-$target"
  # The scratch files of the targets (and an FMU's unpacked folder) go under the work folder.
  if ! TMPDIR="$work/tmp-$target" "$build_dir/fuzz/${target}_fuzz" "${flags[@]}" "$corpus" \
       >"$work/$target.log" 2>&1; then
    result=FINDING
  fi
  # A wire_layout run that stops on a finding leaves its segment (hiltwin-wire-fuzz-<pid>) behind.
  if [[ $target == wire_layout ]]; then rm -f /dev/shm/hiltwin-wire-fuzz-*; fi
  echo "$result" >"$work/$target.result"
}
# One target per core at a time: each run is single-threaded, and its seed and time bound make
# it the same run beside another as alone (how many inputs it gets through in its time varies
# with the load, as it does between machines).
running=0
for target in "${targets[@]}"; do
  run_target "$target" &
  if ((++running >= $(nproc))); then
    wait -n || true
    running=$((running - 1))
  fi
done
wait
failed=()
printf '\n%-22s %10s %8s %8s %s\n' target executions cov ft result
for target in "${targets[@]}"; do
  log="$work/$target.log"
  result=$(<"$work/$target.result")
  [[ $result == ok ]] || failed+=("$target")
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  printf '%-22s %10s %8s %8s %s\n' "$target" "${runs:-?}" "${cov:-?}" "${ft:-?}" "$result"
  if [[ $result != ok ]]; then
    mkdir -p "$findings"
    cp "$log" "$findings/$target.log"
    for artifact in "$work/findings/$target-"*; do
      if [[ -e "$artifact" ]]; then cp "$artifact" "$findings/"; fi
    done
    grep -m 20 -E 'ERROR|FINDING|SUMMARY|^#[0-9]+ .* in hiltwin' "$log" | sed 's/^/    /' || true
  fi
  if [[ -n "$keep_dir" ]]; then
    mkdir -p "$keep_dir/$target"
    cp -r "$work/corpus-$target/." "$keep_dir/$target/"
  fi
done

if [[ ${#failed[@]} -gt 0 ]]; then
  echo "fuzz.sh: findings in: ${failed[*]}; the inputs and logs are in $findings/" >&2
  echo "fuzz.sh: reproduce with $build_dir/fuzz/<target>_fuzz $findings/<file>; then fix" \
       "the parser and add the input as a regression case (docs/fuzzing.md)" >&2
  exit 1
fi
echo "fuzz.sh: ${#targets[@]} targets, ${seconds} s each, no findings"
