#!/usr/bin/env bash
# Flakiness hunt (docs/testing.md, Flakiness): runs the quick tier's tests (ctest -LE long) of an
# existing build several times back to back while stress-ng keeps every CPU busy, and names each
# test that failed in any run with how often. A test that fails once is a bug to fix.
# Usage: scripts/under_load.sh [--runs N] [--build-dir DIR] [--no-load] [-- CTEST_OPTIONS...]
#   --runs N         how many runs (default 5)
#   --build-dir DIR  the tree to test (default build/; build it first: bash scripts/test.sh)
#   --no-load        the same runs without stress-ng (a baseline)
#   CTEST_OPTIONS    replace the default selection (-LE long), e.g. -- -R 'HilCli[.]'
# Exit 0 when every run passed, 1 when any test failed, 2 on bad usage.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=5
build_dir="$root/build"
load=1
selection=(-LE long)
while [[ $# -gt 0 ]]; do
  case $1 in
    --runs) runs=${2:?--runs needs a number}; shift 2 ;;
    --build-dir) build_dir=${2:?--build-dir needs a folder}; shift 2 ;;
    --no-load) load=0; shift ;;
    --) shift; selection=("$@"); break ;;
    -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "under_load: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [[ ! $runs =~ ^[1-9][0-9]*$ ]]; then
  echo "under_load: --runs wants a positive whole number, not '$runs'" >&2
  exit 2
fi
[[ -f "$build_dir/CTestTestfile.cmake" ]] || {
  echo "under_load: $build_dir holds no tests: build it first (bash scripts/test.sh)" >&2; exit 2; }
cpus=$(nproc)
failures=$(mktemp)
stress_pid=""
cleanup() {
  [[ -n $stress_pid ]] && kill "$stress_pid" 2>/dev/null && wait "$stress_pid" 2>/dev/null
  rm -f "$failures"
}
trap cleanup EXIT
if ((load)); then
  command -v stress-ng >/dev/null || {
    echo "under_load: stress-ng is missing: bash scripts/setup.sh installs it" >&2; exit 2; }
  stress-ng --cpu "$cpus" --quiet &
  stress_pid=$!
  echo "== under_load: stress-ng --cpu $cpus (pid $stress_pid) beside every run"
fi
rows=()
for ((run = 1; run <= runs; ++run)); do
  echo "== under_load: run $run of $runs: ctest -j $cpus ${selection[*]}"
  start=$SECONDS
  status=passed
  ctest --test-dir "$build_dir" -j "$cpus" --output-on-failure "${selection[@]}" || status=FAILED
  if [[ $status == FAILED ]]; then
    # LastTestsFailed.log: one "number:Suite.Name" line per failed test of this run.
    cut -d: -f2- "$build_dir/Testing/Temporary/LastTestsFailed.log" >>"$failures"
  fi
  rows+=("$run" "$status" "$((SECONDS - start))")
done
echo "== under_load: $runs runs$( ((load)) && echo " under stress-ng --cpu $cpus")"
printf '%-5s %-8s %10s\n' run result seconds
printf '%-5s %-8s %10s\n' "${rows[@]}"
if [[ -s $failures ]]; then
  echo "under_load: failed (runs out of $runs):" >&2
  sort "$failures" | uniq -c | sort -rn >&2
  exit 1
fi
echo "under_load: every test passed in every run"
