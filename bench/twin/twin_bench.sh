#!/usr/bin/env bash
# Twin-level benchmarks (figures go to docs/BENCHMARKS.md):
#  1. virtual-time speed: 10 min of the 4 kHz RELbot twin (2.4 M cycles) with emulated I/O,
#     QoS and the CSV log on; target <= 1.2 s (>= 500x real time).
#  2. real time at a high rate (default 20 kHz, 10 s), alternating with cyclictest at the same
#     rate and priority: miss % of each and the ratio (target: within 1.2x of cyclictest).
#     A deadline miss of `hiltwin run` (catch-up policy, the default) is every release whose
#     step ended more than one period late; after a stall of L µs that is about floor(L / P)
#     releases. cyclictest skips the periods a stall swallowed and records one late wake-up,
#     so its peer figure is the same count: each histogram sample of latency L > P stands for
#     floor(L / P) releases that passed while it was held up (samples beyond the 20 ms
#     histogram count as 20 ms, a lower bound). The raw late wake-ups are printed too.
# Usage: bench/twin/twin_bench.sh [build_dir] [rate_hz] [seconds] [rounds]
set -euo pipefail
build=${1:-build}; rate=${2:-20000}; seconds=${3:-10}; rounds=${4:-2}
hiltwin="$build/hiltwin"
[[ -x "$hiltwin" ]] || { echo "build first: bash scripts/build.sh" >&2; exit 2; }
command -v cyclictest >/dev/null || { echo "cyclictest missing: apt-get install rt-tests" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
json() { sed -n "s/^  \"$2\": \\([^,]*\\),\\?$/\\1/p" "$1" | head -1; }

echo "== virtual-time speed: 600 s of 4 kHz twin, mock I/O, QoS, CSV log"
start=$(date +%s.%N)
"$hiltwin" run --clock virtual --duration 600 --log "$tmp/v.csv" --report "$tmp/v.json" --no-progress >/dev/null
end=$(date +%s.%N)
wall=$(echo "$end - $start" | bc -l)
echo "  whole command: $(printf %.2f "$wall") s; loop only: $(json "$tmp/v.json" wall_time_s) s; rows: $(json "$tmp/v.json" log_rows_written) written, $(json "$tmp/v.json" log_rows_dropped) dropped"
echo "  speed-up vs real time (whole command): $(printf %.0f "$(echo "600 / $wall" | bc -l)")x"
"$hiltwin" run --clock virtual --duration 600 --report "$tmp/n.json" --no-progress >/dev/null
echo "  without the log: loop $(json "$tmp/n.json" wall_time_s) s"

period_us=$(( 1000000 / rate ))
loops=$(( rate * seconds ))
echo "== real time at $rate Hz, $seconds s, SCHED_FIFO 90, alternating with cyclictest (rounds: $rounds)"
for round in $(seq 1 "$rounds"); do
  set +e
  "$hiltwin" run --rate "$rate" --duration "$seconds" --priority 90 --report "$tmp/r.json" --no-progress >/dev/null
  set -e
  ours=$(json "$tmp/r.json" miss_pct)
  cyclictest -m -q -p90 -i"$period_us" -l"$loops" -h20000 > "$tmp/c.txt"
  read -r late passed < <(awk -v p="$period_us" '
    /^[0-9]/ { b = $1 + 0; if (b > p) { late += $2; passed += $2 * int(b / p) } }
    /Histogram Overflows/ { late += $4; passed += $4 * int(20000 / p) }
    END { print late + 0, passed + 0 }' "$tmp/c.txt")
  theirs=$(echo "100 * $passed / $loops" | bc -l)
  ratio=$(if [[ $(echo "$theirs > 0" | bc) == 1 ]]; then printf %.2f "$(echo "$ours / $theirs" | bc -l)"; else echo n/a; fi)
  printf '  round %d: hiltwin run miss %.3f %% (p99 response %s ns) | cyclictest: %d late wake-ups, %d releases passed while late = %.3f %% | ratio %s\n' \
    "$round" "$ours" "$(sed -n '/"response_ns"/,/}/s/^ *"p99": \([0-9]*\).*/\1/p' "$tmp/r.json")" "$late" "$passed" "$theirs" "$ratio"
done
