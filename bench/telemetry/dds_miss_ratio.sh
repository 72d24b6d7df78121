#!/usr/bin/env bash
# The miss ratio of `hiltwin run` at 4 kHz on the real clock with DDS telemetry publishing at
# 50 Hz (and a monitor subscribed to it) against the same run without telemetry, alternating
# off/on for several rounds so a noisy minute hits both. Usage:
#   bash bench/telemetry/dds_miss_ratio.sh [BUILD_DIR] [SECONDS_PER_RUN] [ROUNDS] [LOOP_CPU]
# Uses the loopback Cyclone configuration shipped in config/ and DDS domain 77. Both runs pin
# the loop to LOOP_CPU (default: the last CPU), as a real-time set-up would: the telemetry
# thread and Cyclone's threads then run on the other CPUs (docs/architecture.md).
set -euo pipefail
build=${1:-build}
seconds=${2:-20}
rounds=${3:-3}
loop_cpu=${4:-$(($(nproc) - 1))}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
hiltwin="$build/hiltwin"
export CYCLONEDDS_URI="file://$repo/config/cyclonedds-loopback.xml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() {  # field FILE KEY: a top-level number of the run report
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"
}
p99() {
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['latency_ns']['p99'] / 1000)" "$1"
}

declare -a off_pct on_pct
for ((r = 1; r <= rounds; ++r)); do
  "$hiltwin" run --rate 4000 --duration "$seconds" --cpu "$loop_cpu" --no-progress --report "$work/off.json" \
    >/dev/null || true
  "$hiltwin" monitor --domain 77 --duration $((seconds + 5)) >/dev/null 2>&1 &
  monitor=$!
  "$hiltwin" run --rate 4000 --duration "$seconds" --cpu "$loop_cpu" --no-progress --report "$work/on.json" \
    --telemetry dds:77 --namespace bench --telemetry-rate 50 >/dev/null || true
  kill "$monitor" 2>/dev/null || true
  wait "$monitor" 2>/dev/null || true
  off_pct+=("$(field "$work/off.json" miss_pct)")
  on_pct+=("$(field "$work/on.json" miss_pct)")
  printf 'round %d: off %s %% misses (%s of %s), p99 latency %.1f us | DDS on %s %% misses (%s of %s), p99 latency %.1f us\n' \
    "$r" "${off_pct[-1]}" "$(field "$work/off.json" deadline_misses)" \
    "$(field "$work/off.json" cycles_run)" "$(p99 "$work/off.json")" "${on_pct[-1]}" \
    "$(field "$work/on.json" deadline_misses)" "$(field "$work/on.json" cycles_run)" \
    "$(p99 "$work/on.json")"
done
python3 - "${off_pct[@]}" -- "${on_pct[@]}" <<'PY'
import statistics, sys
args = sys.argv[1:]
cut = args.index("--")
off = [float(x) for x in args[:cut]]
on = [float(x) for x in args[cut + 1:]]
mo, mn = statistics.median(off), statistics.median(on)
print(f"median miss ratio: without telemetry (peer) {mo:.4f} %, with DDS at 50 Hz {mn:.4f} %, "
      f"difference {mn - mo:+.4f} points")
PY
