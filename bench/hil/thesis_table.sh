#!/usr/bin/env bash
# Reproduces the thesis's figures on this machine, one row per figure of docs/RESULTS.md:
# open-loop twin vs reference (thesis 5.2-5.3, 5.6), the encoder link (Table 5.2), the twin's
# missed deadlines under the controller at 1/4/8/16 kHz (Table 5.1) and the closed loop (7.2).
# Real-time runs: about 16 minutes with the defaults. Prints a markdown table and keeps every
# log and report in the output folder.
set -euo pipefail

usage() {
  cat <<'TEXT'
usage: bench/hil/thesis_table.sh [OUT_DIR]
  OUT_DIR  where logs, reports and the table go (default: a new folder under /tmp)
environment:
  HILTWIN            the binary (default: build/hiltwin of this checkout)
  OPENLOOP_S         open-loop run length in seconds (default 600, the thesis's 10 minutes)
  TABLE51_S          length of each Table 5.1 run in seconds (default 60)
TEXT
}
[[ "${1:-}" == "-h" || "${1:-}" == "--help" ]] && { usage; exit 0; }

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
hiltwin="${HILTWIN:-$root/build/hiltwin}"
[[ -x "$hiltwin" ]] || { echo "no hiltwin binary at $hiltwin: build first (bash scripts/build.sh)" >&2; exit 2; }
out="${1:-$(mktemp -d /tmp/hiltwin-thesis-XXXXXX)}"
mkdir -p "$out"
openloop_s="${OPENLOOP_S:-600}"
table51_s="${TABLE51_S:-60}"
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2], {'d': d}))" "$@"; }

echo "== open loop, ${openloop_s} s (thesis 5.2, 5.3, 5.6)" >&2
"$hiltwin" hil --mode openloop --duration "$openloop_s" --no-progress --log-dir "$out/openloop" \
  --report "$out/openloop/hil.json" > "$out/openloop.txt" || true
"$hiltwin" run --clock virtual --io mock --input "$out/openloop/ecs.csv" --input-rate 1000 \
  --rate 4000 --duration "$openloop_s" --no-progress --log "$out/openloop/ref.csv" > /dev/null
# The openloop profile repeats every 36 s: the delay search must stay well inside one
# repetition, or it finds the next one (a 36 s "delay"). The twin's delay is a few ms.
"$hiltwin" assess --sim "$out/openloop/ref.csv:wheel_right_m" \
  --exp "$out/openloop/ecs.csv:wheel_right_m" --max-delay 0.01 --json > "$out/openloop/assess.json"

echo "== encoder link, 720000 messages (thesis Table 5.2)" >&2
"$hiltwin" io-test --io mock --frames 720000 --json > "$out/io_test.json"

echo "== closed loop (thesis 7.2)" >&2
"$hiltwin" hil --no-progress --log-dir "$out/closedloop" --report "$out/closedloop/hil.json" \
  > "$out/closedloop.txt" || true

for khz in 1 4 8 16; do
  echo "== Table 5.1: twin at ${khz} kHz for ${table51_s} s under the controller" >&2
  "$hiltwin" hil --mode openloop --twin-rate "${khz}000" --duration "$table51_s" --no-progress \
    --report "$out/table51_${khz}k.json" > "$out/table51_${khz}k.txt" || true
done

a="$out/openloop/assess.json"
range=$(json "$a" "d['time_domain']['eps_t'] / 0.05")
{
  echo "| figure | this machine | thesis |"
  echo "|---|---|---|"
  echo "| open-loop RMS error, raw | $(json "$a" "'%.3g m = %.3g %% of %.2f m' % (d['time_domain']['e_t'], 100*d['time_domain']['e_t']/$range, $range)") | 9.22e-4 m = 7.29e-3 % |"
  echo "| open-loop RMS error, delay-compensated | $(json "$a" "'%.3g m = %.3g %%, delay %.3f ms' % (d['time_domain_compensated']['e_t'], 100*d['time_domain_compensated']['e_t']/$range, 1e3*d['delay_s'])") | 9.71e-5 m = 7.68e-4 %, 2 ms |"
  echo "| credibility twin vs reference (raw / compensated) | $(json "$a" "'%.6f / %.6f' % (d['time_domain']['eta'], d['time_domain_compensated']['eta'])") | 0.999978 |"
  echo "| encoder messages sent / received / missed | $(json "$out/io_test.json" "'%d / %d / %d' % (d['encoder_messages_sent'], d['encoder_messages_received'], d['encoder_messages_missed'])") | 720,000 / 720,000 / 0 |"
  for khz in 1 4 8 16; do
    echo "| twin misses at ${khz} kHz, ${table51_s} s | $(json "$out/table51_${khz}k.json" "'%d of %d (%.3g %%), verdict %s' % (d['twin']['deadline_misses'], d['twin']['cycles_run'], d['twin']['miss_pct'], d['twin']['verdict'])") | see Table 5.1 |"
  done
  echo "| closed-loop tracking error (max left / right, rms, final) | $(json "$out/closedloop/hil.json" "'%.3f / %.3f mm, %.3f mm, %.4f mm' % (1e3*d['tracking_error_max_m']['left'], 1e3*d['tracking_error_max_m']['right'], 1e3*d['tracking_error_rms_m'], 1e3*d['final_error_m'])") | < 3 mm, no steady-state error |"
} | tee "$out/table.md"
echo "logs and reports: $out" >&2
