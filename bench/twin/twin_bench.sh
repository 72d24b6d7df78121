#!/usr/bin/env bash
# Twin-level benchmarks (figures go to docs/BENCHMARKS.md):
#  1. virtual-time speed: 10 min of the 4 kHz RELbot twin (2.4 M cycles) with emulated I/O and
#     QoS, with the CSV log on and without it, 3 runs each (alternating): every run's whole
#     command and loop time, then the medians against the targets (issue 36: the whole command
#     <= 0.8 s with the log, <= 0.5 s without).
#  2. real time at a high rate (default 20 kHz, 10 s), alternating with cyclictest at the same
#     rate and priority, ROUNDS rounds (default 5): miss % of each and the ratio per round, then
#     the median ratio (target: within 1.2x of cyclictest).
#     A deadline miss of `hiltwin run` (catch-up policy, the default) is every release whose
#     step ended more than one period late; after a stall of L µs that is about floor(L / P)
#     releases. cyclictest skips the periods a stall swallowed and records one late wake-up,
#     so its peer figure is the same count: each histogram sample of latency L > P stands for
#     floor(L / P) releases that passed while it was held up (samples beyond the 20 ms
#     histogram count as 20 ms, a lower bound). The raw late wake-ups are printed too.
# Usage: bench/twin/twin_bench.sh [build_dir] [rate_hz] [seconds] [rounds]
set -euo pipefail
build=${1:-build}; rate=${2:-20000}; seconds=${3:-10}; rounds=${4:-5}
hiltwin="$build/hiltwin"
[[ -x "$hiltwin" ]] || { echo "build first: bash scripts/build.sh" >&2; exit 2; }
command -v cyclictest >/dev/null || { echo "cyclictest missing: apt-get install rt-tests" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
json() { sed -n "s/^  \"$2\": \\([^,]*\\),\\?$/\\1/p" "$1" | head -1; }

# The median of the numbers on stdin (the middle one; the upper middle of an even count).
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR) print v[int(NR / 2) + 1] }'; }
# Whole command and loop seconds of one 600 s virtual run; extra flags (the log) after $1.
virtual_run() {
  local report=$1; shift
  local start end
  start=$(date +%s.%N)
  "$hiltwin" run --clock virtual --duration 600 --report "$report" --no-progress "$@" >/dev/null
  end=$(date +%s.%N)
  printf '%.2f %.2f\n' "$(echo "$end - $start" | bc -l)" "$(json "$report" wall_time_s)"
}

echo "== virtual-time speed: 600 s of the 4 kHz twin, mock I/O, QoS; with the CSV log and without, 3 runs each"
: >"$tmp/with"; : >"$tmp/without"
for run in 1 2 3; do
  read -r whole loop < <(virtual_run "$tmp/v.json" --log "$tmp/v.csv")
  echo "$whole $loop" >>"$tmp/with"
  echo "  run $run with the log: whole command $whole s, loop $loop s; rows: $(json "$tmp/v.json" log_rows_written) written, $(json "$tmp/v.json" log_rows_dropped) dropped"
  rm -f "$tmp/v.csv"
  read -r whole loop < <(virtual_run "$tmp/n.json")
  echo "$whole $loop" >>"$tmp/without"
  echo "  run $run without the log: whole command $whole s, loop $loop s"
done
for variant in with without; do
  target=0.8; [[ $variant == without ]] && target=0.5
  whole=$(cut -d' ' -f1 "$tmp/$variant" | median); loop=$(cut -d' ' -f2 "$tmp/$variant" | median)
  met=$([[ $(echo "$whole <= $target" | bc) == 1 ]] && echo met || echo "NOT met")
  printf '  median of 3 %s the log: whole command %s s (target <= %s s: %s; %.0fx real time), loop %s s\n' \
    "$variant" "$whole" "$target" "$met" "$(echo "600 / $whole" | bc -l)" "$loop"
done

period_us=$(( 1000000 / rate ))
loops=$(( rate * seconds ))
echo "== real time at $rate Hz, $seconds s, SCHED_FIFO 90, alternating with cyclictest (rounds: $rounds)"
ratios=()
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
  ratios+=("$ratio")
  printf '  round %d: hiltwin run miss %.3f %% (p99 response %s ns) | cyclictest: %d late wake-ups, %d releases passed while late = %.3f %% | ratio %s\n' \
    "$round" "$ours" "$(sed -n '/"response_ns"/,/}/s/^ *"p99": \([0-9]*\).*/\1/p' "$tmp/r.json")" "$late" "$passed" "$theirs" "$ratio"
done
# A round whose cyclictest missed nothing has no ratio (n/a): the median is of the others.
valid=$(printf '%s\n' "${ratios[@]}" | grep -v n/a || true)
if [[ -n $valid ]]; then
  med=$(echo "$valid" | median)
  met=$([[ $(echo "$med <= 1.2" | bc) == 1 ]] && echo met || echo "NOT met")
  echo "  median miss ratio hiltwin run / cyclictest-equivalent over $(echo "$valid" | wc -l) of $rounds rounds: $med (per round: ${ratios[*]}; target <= 1.2: $met)"
else
  echo "  median miss ratio: n/a (cyclictest missed nothing in any of $rounds rounds; per round: ${ratios[*]})"
fi
