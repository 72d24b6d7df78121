#!/usr/bin/env bash
# Instructions per twin cycle of the whole command, by function, load-independent (callgrind):
# runs `hiltwin run --clock virtual` for D and 2D seconds with the given extra flags and prints
# (I(2D) - I(D)) / (rate * D) in total (every thread: the loop, the log writer, the control
# thread) and per function (self cost), so start-up and shut-down cancel. The cross-check of
# hiltwin_bench_cycle's whole cycle (the loop thread alone), and where its instructions go.
# Usage: bench/cycle/cycle_functions.sh <hiltwin binary> [seconds=2] [extra run flags...]
set -euo pipefail
bin=$1; d=${2:-2}; shift; shift || true
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for s in "$d" "$((2 * d))"; do
  chrt --idle 0 valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$s" \
    "$bin" run --clock virtual --duration "$s" --no-progress "$@" >/dev/null 2>&1 || true
done
python3 - "$tmp/cg.$d" "$tmp/cg.$((2 * d))" "$d" "$@" <<'PY'
import re, subprocess, sys
def load(f):
    out = subprocess.run(['callgrind_annotate', '--auto=no', '--threshold=100', f],
                         capture_output=True, text=True).stdout
    d, total = {}, 0
    for line in out.splitlines():
        m = re.match(r'\s*([\d,]+)\s+(?:\([^)]*\)\s+)?(.*)', line)
        if not m: continue
        v = int(m.group(1).replace(',', ''))
        if 'PROGRAM TOTALS' in line: total = v; continue
        name = re.sub(r'\s*\[[^\]]*\]\s*$', '', m.group(2))
        name = name.split(':', 1)[1] if ':' in name.split('(')[0] else name
        d[name[:120]] = d.get(name[:120], 0) + v
    return total, d
ta, a = load(sys.argv[1]); tb, b = load(sys.argv[2]); secs = float(sys.argv[3])
rate = 4000.0
extra = sys.argv[4:]
if '--rate' in extra: rate = float(extra[extra.index('--rate') + 1])
n = rate * secs
print(f"instructions per cycle (all threads): {(tb - ta) / n:.0f}   [{int(n)} cycles difference]")
rows = sorted(((b.get(k, 0) - a.get(k, 0)) / n, k) for k in set(a) | set(b))
for v, k in reversed(rows):
    if v >= 5: print(f"{v:8.0f}  {k}")
PY
