#!/usr/bin/env bash
# Instructions per executive cycle (empty step, virtual clock, one observer), by callgrind:
# two runs with different cycle counts, the difference divided by the extra cycles.
# Usage: bench/executive/callgrind_overhead.sh [build_dir]   (target: <= 1000 instr/cycle)
set -euo pipefail
build=${1:-build}
exe="$build/bench/executive/hiltwin_bench_overhead"
[[ -x "$exe" ]] || { echo "build first: cmake --build $build --target hiltwin_bench_overhead" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "valgrind missing: apt-get install valgrind" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
count() {
  valgrind --tool=callgrind --callgrind-out-file="$tmp/out.$1" "$exe" "$1" >/dev/null 2>"$tmp/err.$1"
  grep -E '^(summary|totals):' "$tmp/out.$1" | head -1 | awk '{print $2}'
}
n1=100000; n2=300000
i1=$(count $n1); i2=$(count $n2)
per=$(( (i2 - i1) / (n2 - n1) ))
echo "hiltwin executive overhead: $per instructions/cycle (callgrind, I($n2)=$i2, I($n1)=$i1; target <= 1000)"
