#!/usr/bin/env bash
# Instructions per cycle by callgrind (empty step, virtual clock): two runs with different
# cycle counts, the difference divided by the extra cycles, for three assemblies:
#   executive  the executive alone, one observer     (target <= 1000; 396 before io_ns, +50 allowed)
#   qos        the per-cycle work of `hiltwin run` before the run assembly, minus the model
#   session    runtime::RunSession, empty task, same rules: today's per-cycle work
# session - qos is what the run assembly's lifecycle rules and status plumbing cost per cycle.
# Usage: bench/executive/callgrind_overhead.sh [build_dir]
set -euo pipefail
build=${1:-build}
exe="$build/bench/executive/hiltwin_bench_overhead"
[[ -x "$exe" ]] || { echo "build first: cmake --build $build --target hiltwin_bench_overhead" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "valgrind missing: apt-get install valgrind" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
count() {
  valgrind --tool=callgrind --callgrind-out-file="$tmp/out.$1.$2" "$exe" "$1" "$2" >/dev/null 2>"$tmp/err.$1.$2"
  # Threads write one file each (session mode): sum their totals.
  cat "$tmp"/out."$1"."$2"* | awk '/^summary:/ { s += $2 } END { print s }'
}
n1=100000; n2=300000
declare -A per
for mode in executive qos session; do
  i1=$(count $n1 $mode); i2=$(count $n2 $mode)
  per[$mode]=$(( (i2 - i1) / (n2 - n1) ))
  echo "hiltwin $mode overhead: ${per[$mode]} instructions/cycle (callgrind, I($n2)=$i2, I($n1)=$i1)"
done
echo "executive target <= 1000: $([[ ${per[executive]} -le 1000 ]] && echo met || echo NOT met); rise over 396: $(( per[executive] - 396 )) (<= 50: $([[ $(( per[executive] - 396 )) -le 50 ]] && echo met || echo NOT met))"
echo "session - qos = $(( per[session] - per[qos] )) instructions/cycle: the run assembly's lifecycle rules and status plumbing"
