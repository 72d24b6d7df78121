#!/usr/bin/env bash
# Reproduces the thesis's figures on this machine, one row per figure of docs/RESULTS.md:
# open-loop twin vs reference (thesis 5.2-5.3, 5.6), the encoder link (Table 5.2), the twin's
# missed deadlines under the controller at 1/4/8/16 kHz (Table 5.1) and the closed loop (7.2).
#
# Real-time rows (--clock realtime) run RUNS times each, interleaved round by round; the table
# gives their median and range. Lockstep rows (--clock virtual: closed loop and open loop) run
# once per figure, and a second time to check that both runs are identical. The encoder-link
# row (io-test over mock) is deterministic and runs once.
# With the defaults this takes about 75 minutes (RUNS x (600 s + 4 x 60 s + 12 s) + overhead).
# Every report, assess output and log stays in OUT_DIR; the per-cycle CSV logs of a 600 s run
# are several hundred MB.
set -euo pipefail

usage() {
  cat <<'TEXT'
usage: bench/hil/thesis_table.sh [OUT_DIR]
  OUT_DIR  where logs, reports and the table go (default: a new folder under /tmp)
environment:
  HILTWIN            the binary (default: build/hiltwin of this checkout)
  RUNS               real-time runs per row (default 5)
  OPENLOOP_S         open-loop run length in seconds (default 600, the thesis's 10 minutes)
  TABLE51_S          length of each Table 5.1 run in seconds (default 60)
  SUMMARY_ONLY=1     only (re)write the table and summary from the runs already in OUT_DIR
  COPY_TO            also copy the small files (reports, assess JSON, summary) to this folder
outputs in OUT_DIR:
  table.md           the markdown table of docs/RESULTS.md
  summary.json       every figure of every run, with median, min, max and N per figure
  runs.csv           one row per run and figure
  lockstep_identical.txt   whether the two lockstep runs of each figure are identical
TEXT
}
[[ "${1:-}" == "-h" || "${1:-}" == "--help" ]] && { usage; exit 0; }

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
hiltwin="${HILTWIN:-$root/build/hiltwin}"
[[ "${SUMMARY_ONLY:-0}" == 1 || -x "$hiltwin" ]] || { echo "no hiltwin binary at $hiltwin: build first (bash scripts/build.sh)" >&2; exit 2; }
out="${1:-$(mktemp -d /tmp/hiltwin-thesis-XXXXXX)}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
runs="${RUNS:-5}"
openloop_s="${OPENLOOP_S:-600}"
table51_s="${TABLE51_S:-60}"
log() { echo "[$(date -u +%H:%M:%S)] $*" >&2; }

# The reference: the same RELbot model on the virtual clock, driven by the duty the ECS logged
# (at its 1 kHz), then assess compares the right wheel as the thesis does. The openloop profile
# repeats every 36 s: the delay search must stay well inside one repetition, or it finds the
# next one (a 36 s "delay"). The twin's delay is a few ms.
reference_and_assess() {  # DIR SECONDS
  local d="$1" s="$2"
  "$hiltwin" run --clock virtual --io mock --input "$d/ecs.csv" --input-rate 1000 \
    --rate 4000 --duration "$s" --no-progress --log "$d/ref.csv" > "$d/ref.out"
  "$hiltwin" assess --sim "$d/ref.csv:wheel_right_m" --exp "$d/ecs.csv:wheel_right_m" \
    --max-delay 0.01 --json > "$d/assess.json"
  offset_per_second "$d"
}

# offset.csv: per second of the run, the mean of (ECS-measured right wheel - reference right
# wheel) and the twin's worst wake-up latency and misses in that second. Shows what a stall
# does to the open loop.
offset_per_second() {  # DIR
  python3 - "$1" <<'PY'
import csv, sys, math
d = sys.argv[1]
ref = {}
with open(f"{d}/ref.csv") as f:
    r = csv.reader(f); h = next(r); ti = h.index("time_s"); wi = h.index("wheel_right_m")
    for row in r:
        k = round(float(row[ti]) * 4000)
        if k % 4 == 0:
            ref[k // 4] = float(row[wi])
sec = {}
with open(f"{d}/ecs.csv") as f:
    r = csv.reader(f); h = next(r); ti = h.index("time_s"); wi = h.index("wheel_right_m")
    for row in r:
        t = float(row[ti]); k = round(t * 1000)
        if k in ref:
            s = sec.setdefault(int(math.floor(t + 1e-9)), [0.0, 0, 0.0, 0])
            s[0] += float(row[wi]) - ref[k]; s[1] += 1
with open(f"{d}/twin.csv") as f:
    r = csv.reader(f); h = next(r); ti = h.index("time_s"); li = h.index("latency_us"); mi = h.index("missed")
    for row in r:
        s = sec.setdefault(int(math.floor(float(row[ti]) - 1e-9)), [0.0, 0, 0.0, 0])
        s[2] = max(s[2], float(row[li])); s[3] += int(float(row[mi]))
with open(f"{d}/offset.csv", "w") as f:
    f.write("second,mean_offset_mm,twin_worst_latency_ms,twin_misses\n")
    for k in sorted(sec):
        s = sec[k]
        if s[1]:
            f.write(f"{k},{1e3 * s[0] / s[1]:.4f},{s[2] / 1e3:.3f},{s[3]}\n")
PY
}

openloop_run() {  # DIR CLOCK
  local d="$1" clock="$2"
  mkdir -p "$d"
  cat /proc/loadavg > "$d/loadavg"
  "$hiltwin" hil --clock "$clock" --mode openloop --duration "$openloop_s" --no-progress \
    --log-dir "$d" --report "$d/hil.json" > "$d/hil.txt" || echo "hil exit $?" >> "$d/hil.txt"
  # A run that did not finish (an I/O fault, e.g. a side's heartbeat lost in a long stall) is
  # kept, counted and left out of the medians; its reference would be meaningless.
  if python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d['exit_code'] in (0, 3) and d['ecs']['stop_reason'] == 'finished' else 1)" "$d/hil.json" 2>/dev/null; then
    reference_and_assess "$d" "$openloop_s" || echo "reference or assess failed: exit $?" >> "$d/hil.txt"
  fi
}

closedloop_run() {  # DIR CLOCK
  local d="$1" clock="$2"
  mkdir -p "$d"
  cat /proc/loadavg > "$d/loadavg"
  "$hiltwin" hil --clock "$clock" --no-progress --log-dir "$d" --report "$d/hil.json" \
    > "$d/hil.txt" || echo "hil exit $?" >> "$d/hil.txt"
}

table51_run() {  # FILE_STEM KHZ
  cat /proc/loadavg > "$1.loadavg"
  "$hiltwin" hil --mode openloop --twin-rate "${2}000" --duration "$table51_s" --no-progress \
    --report "$1.json" > "$1.txt" || echo "hil exit $?" >> "$1.txt"
}

if [[ "${SUMMARY_ONLY:-0}" != 1 ]]; then
  {
    echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
    echo "host: $(uname -n), $(nproc) CPUs, kernel $(uname -r) ($(uname -v))"
    echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
    echo "binary: $hiltwin ($("$hiltwin" --version 2>&1 | head -1)), sha256 $(sha256sum "$hiltwin" | cut -c1-16)"
    echo "RUNS=$runs OPENLOOP_S=$openloop_s TABLE51_S=$table51_s"
  } > "$out/machine.txt"

  log "encoder link, 720000 messages (thesis Table 5.2), deterministic: once"
  "$hiltwin" io-test --io mock --frames 720000 --json > "$out/io_test.json"

  for ab in a b; do
    log "lockstep closed loop ($ab)"
    closedloop_run "$out/lockstep/closedloop_$ab" virtual
    log "lockstep open loop, ${openloop_s} s ($ab)"
    openloop_run "$out/lockstep/openloop_$ab" virtual
  done

  for ((i = 1; i <= runs; i++)); do
    log "round $i of $runs: real-time open loop, ${openloop_s} s"
    openloop_run "$out/realtime/openloop_r$i" realtime
    for khz in 1 4 8 16; do
      log "round $i of $runs: Table 5.1, twin at ${khz} kHz for ${table51_s} s"
      mkdir -p "$out/realtime/table51_${khz}k"
      table51_run "$out/realtime/table51_${khz}k/r$i" "$khz"
    done
    log "round $i of $runs: real-time closed loop"
    closedloop_run "$out/realtime/closedloop_r$i" realtime
  done
fi

log "summary"
python3 - "$out" <<'PY'
import csv, glob, hashlib, json, os, re, statistics, sys
out = sys.argv[1]
def load(p):
    with open(p) as f:
        return json.load(f)
def rnum(p):
    m = re.search(r"r(\d+)(\.json)?$", p)
    return int(m.group(1))

# --- lockstep: are the two runs identical? (wall_time_s and the wire name hil-<pid> aside)
def norm(path, rundir):
    s = open(path).read()
    s = re.sub(r'"wall_time_s": *[0-9.eE+-]+', '"wall_time_s": X', s)
    s = re.sub(r"hil-\d+", "hil-PID", s)
    s = s.replace(rundir, "RUNDIR")
    # the start-up message "waiting for the controller ..." appears when one process starts
    # before the other: a start-up race in the terminal text, not a result
    s = re.sub(r"(?m)^hiltwin: waiting for the .*\n", "", s)
    return hashlib.sha256(s.encode()).hexdigest()
identical = {}
lines = []
for fig in ("closedloop", "openloop"):
    a, b = f"{out}/lockstep/{fig}_a", f"{out}/lockstep/{fig}_b"
    if not (os.path.isdir(a) and os.path.isdir(b)):
        continue
    same = True
    for name in sorted(os.listdir(a)):
        if name == "loadavg":   # the machine's load when the run started, not an output
            continue
        if name in ("hil.txt", "ref.out", "twin.out", "ecs.out"):
            kind = "text, normalised"
        elif name.endswith(".json"):
            kind = "JSON, normalised"
        else:
            kind = "bytes"
        ha = norm(f"{a}/{name}", a) if kind != "bytes" else hashlib.sha256(open(f"{a}/{name}", "rb").read()).hexdigest()
        hb = norm(f"{b}/{name}", b) if kind != "bytes" else hashlib.sha256(open(f"{b}/{name}", "rb").read()).hexdigest()
        ok = ha == hb
        same &= ok
        lines.append(f"{fig}: {name:12s} {'identical' if ok else 'DIFFERENT'} ({kind}) sha256 {ha[:16]}")
    identical[fig] = same
with open(f"{out}/lockstep_identical.txt", "w") as f:
    f.write("Two lockstep runs of each figure, compared file by file. JSON and text outputs are\n"
            "compared after removing wall_time_s, the wire name hil-<pid>, the run folder and\n"
            "the start-up line 'waiting for the controller/twin' (whichever process starts first).\n")
    f.write("\n".join(lines) + "\n")
    f.write("".join(f"{k}: {'IDENTICAL' if v else 'NOT IDENTICAL'}\n" for k, v in identical.items()))

# --- per-run figures
def finished(p):
    h = load(p)
    return h["exit_code"] in (0, 3) and h["ecs"]["stop_reason"] == "finished"
failed = {}
def openloop_figs(d):
    h, a = load(f"{d}/hil.json"), load(f"{d}/assess.json")
    td, tc = a["time_domain"], a["time_domain_compensated"]
    f = {
        "e_raw_m": td["e_t"], "e_comp_m": tc["e_t"], "delay_ms": 1e3 * a["delay_s"],
        "eta_raw": td["eta"], "eta_comp": tc["eta"], "range_m": td["eps_t"] / 0.05,
        "twin_misses": h["twin"]["deadline_misses"], "twin_cycles": h["twin"]["cycles_run"],
        "twin_worst_latency_ms": h["twin"]["latency_ns"]["max"] / 1e6,
        "edges": h["ecs"]["encoder_lines"]["edges"],
        "edge_errors": sum(h["ecs"]["encoder_lines"][k] for k in ("illegal_transitions", "too_fast_edges", "resyncs")),
        "link_errors": h["link_errors"],
    }
    if os.path.exists(f"{d}/offset.csv"):
        rows = list(csv.DictReader(open(f"{d}/offset.csv")))
        offs = [float(r["mean_offset_mm"]) for r in rows]
        f["offset_first_s_mm"] = offs[0]
        f["offset_last_s_mm"] = offs[-1]
        f["offset_max_abs_mm"] = max(abs(o) for o in offs)
        # the largest jump of the per-second offset, and the twin's worst wake-up in that second
        j = max(range(1, len(offs)), key=lambda i: abs(offs[i] - offs[i - 1]), default=0)
        f["offset_biggest_jump_mm"] = offs[j] - offs[j - 1] if j else 0.0
        f["offset_biggest_jump_at_s"] = int(rows[j]["second"])
        f["offset_biggest_jump_twin_latency_ms"] = float(rows[j]["twin_worst_latency_ms"])
    return f
def closedloop_figs(d):
    h = load(f"{d}/hil.json")
    return {
        "max_left_mm": 1e3 * h["tracking_error_max_m"]["left"], "max_right_mm": 1e3 * h["tracking_error_max_m"]["right"],
        "rms_mm": 1e3 * h["tracking_error_rms_m"], "final_mm": 1e3 * h["final_error_m"],
        "twin_worst_latency_ms": h["twin"]["latency_ns"]["max"] / 1e6,
        "ecs_worst_latency_ms": h["ecs"]["latency_ns"]["max"] / 1e6,
    }
def table51_figs(p):
    t = load(p)["twin"]
    return {"misses": t["deadline_misses"], "cycles": t["cycles_run"], "miss_pct": t["miss_pct"],
            "longest_run": t["max_consecutive_misses"], "worst_latency_ms": t["latency_ns"]["max"] / 1e6,
            "verdict": t["verdict"]}

rows = {}   # figure -> list of (run, figs)
for d in sorted(glob.glob(f"{out}/realtime/openloop_r*"), key=rnum):
    if os.path.exists(f"{d}/hil.json") and not finished(f"{d}/hil.json"):
        failed.setdefault("openloop_realtime", []).append(rnum(d))
    elif os.path.exists(f"{d}/assess.json"):
        rows.setdefault("openloop_realtime", []).append((rnum(d), openloop_figs(d)))
for d in sorted(glob.glob(f"{out}/realtime/closedloop_r*"), key=rnum):
    if os.path.exists(f"{d}/hil.json") and not finished(f"{d}/hil.json"):
        failed.setdefault("closedloop_realtime", []).append(rnum(d))
    elif os.path.exists(f"{d}/hil.json"):
        rows.setdefault("closedloop_realtime", []).append((rnum(d), closedloop_figs(d)))
for khz in (1, 4, 8, 16):
    for p in sorted(glob.glob(f"{out}/realtime/table51_{khz}k/r*.json"), key=rnum):
        if not finished(p):
            failed.setdefault(f"table51_{khz}k", []).append(rnum(p)); continue
        rows.setdefault(f"table51_{khz}k", []).append((rnum(p), table51_figs(p)))
if os.path.exists(f"{out}/lockstep/openloop_a/assess.json"):
    rows["openloop_lockstep"] = [(1, openloop_figs(f"{out}/lockstep/openloop_a"))]
if os.path.exists(f"{out}/lockstep/closedloop_a/hil.json"):
    rows["closedloop_lockstep"] = [(1, closedloop_figs(f"{out}/lockstep/closedloop_a"))]
io = load(f"{out}/io_test.json") if os.path.exists(f"{out}/io_test.json") else None

def stats(fig, key):
    v = [f[key] for _, f in rows.get(fig, [])]
    if not v:
        return None
    return {"median": statistics.median(v), "min": min(v), "max": max(v), "n": len(v)}
summary = {"machine": open(f"{out}/machine.txt").read().splitlines() if os.path.exists(f"{out}/machine.txt") else [],
           "lockstep_identical": identical, "failed_runs": failed, "figures": {}, "runs": {}}
for fig, lst in rows.items():
    summary["runs"][fig] = [dict(run=r, **f) for r, f in lst]
    summary["figures"][fig] = {k: stats(fig, k) for k, v in lst[0][1].items() if isinstance(v, (int, float))}
if io:
    summary["io_test"] = {k: io[k] for k in ("encoder_messages_sent", "encoder_messages_received", "encoder_messages_missed")}
with open(f"{out}/summary.json", "w") as f:
    json.dump(summary, f, indent=1)
with open(f"{out}/runs.csv", "w") as f:
    w = csv.writer(f)
    w.writerow(["figure", "run", "key", "value"])
    for fig, lst in rows.items():
        for r, figs in lst:
            for k, v in figs.items():
                w.writerow([fig, r, k, v])

# --- the markdown table
def g(x, fmt):
    return fmt % x
def rt(fig, key, fmt, scale=1.0):
    s = stats(fig, key)
    if not s:
        return "not run"
    return f"{fmt % (scale * s['median'])} ({fmt % (scale * s['min'])}–{fmt % (scale * s['max'])}, N={s['n']})"
def ls(fig, key, fmt, scale=1.0):
    s = stats(fig, key)
    return fmt % (scale * s["median"]) if s else "not run"
T = []
T.append("| figure | real time: median (range, N runs) | lockstep (exact) | thesis |")
T.append("|---|---|---|---|")
T.append(f"| open-loop RMS position error, raw (§5.2) | {rt('openloop_realtime', 'e_raw_m', '%.3g', 1e3)} mm | {ls('openloop_lockstep', 'e_raw_m', '%.3g', 1e3)} mm | 0.922 mm |")
T.append(f"| open-loop RMS position error, delay-compensated (§5.3) | {rt('openloop_realtime', 'e_comp_m', '%.3g', 1e3)} mm | {ls('openloop_lockstep', 'e_comp_m', '%.3g', 1e3)} mm | 0.0971 mm |")
T.append(f"| open-loop delay, twin behind the reference (§5.3) | {rt('openloop_realtime', 'delay_ms', '%.3f')} ms | {ls('openloop_lockstep', 'delay_ms', '%.3f')} ms | 2 ms |")
T.append(f"| credibility η, raw (§5.6; Kp 0.05 of this run's range) | {rt('openloop_realtime', 'eta_raw', '%.10f')} | {ls('openloop_lockstep', 'eta_raw', '%.10f')} | 0.999978 |")
T.append(f"| open-loop offset in the last second of the run | {rt('openloop_realtime', 'offset_last_s_mm', '%.3f')} mm | {ls('openloop_lockstep', 'offset_last_s_mm', '%.3f')} mm | — |")
T.append(f"| encoder edges decoded in the open-loop run; illegal / too fast / resyncs | {rt('openloop_realtime', 'edges', '%d')}; {rt('openloop_realtime', 'edge_errors', '%d')} | {ls('openloop_lockstep', 'edges', '%d')}; {ls('openloop_lockstep', 'edge_errors', '%d')} | — |")
if io:
    T.append(f"| encoder messages sent / received / missed (Table 5.2; deterministic, 1 run) | {io['encoder_messages_sent']:,} / {io['encoder_messages_received']:,} / {io['encoder_messages_missed']:,} | same | 720,000 / 720,000 / 0 |")
thesis51 = {1: "1 of 600,000 = 1.66e-4 %", 4: "9 of 2,400,000 = 3.75e-4 %", 8: "325,762 of 4,800,000 = 6.78 %", 16: "1,630,674 of 9,600,000 = 17.0 %"}
for khz in (1, 4, 8, 16):
    fig = f"table51_{khz}k"
    cyc = stats(fig, "cycles")
    cycs = f" of {int(cyc['median']):,}" if cyc else ""
    T.append(f"| twin's missed deadlines at {khz} kHz, under the controller (Table 5.1) | {rt(fig, 'misses', '%d')}{cycs} = {rt(fig, 'miss_pct', '%.3f')} % | — (no deadlines) | {thesis51[khz]} |")
T.append(f"| closed-loop max tracking error, per wheel (§7.2) | {rt('closedloop_realtime', 'max_right_mm', '%.2f')} mm | {ls('closedloop_lockstep', 'max_right_mm', '%.3f')} mm | below 3 mm |")
T.append(f"| closed-loop RMS tracking error | {rt('closedloop_realtime', 'rms_mm', '%.3f')} mm | {ls('closedloop_lockstep', 'rms_mm', '%.3f')} mm | — |")
T.append(f"| closed-loop final error | {rt('closedloop_realtime', 'final_mm', '%.4f')} mm | {ls('closedloop_lockstep', 'final_mm', '%.4f')} mm | no steady-state error |")
if failed:
    T.append("")
    T.append("Runs that did not finish (an I/O fault), left out of the medians: " + "; ".join(f"{k} round {', '.join(map(str, v))}" for k, v in failed.items()) + ".")
if identical:
    T.append("")
    T.append("Lockstep runs repeated and compared: " + ", ".join(f"{k} {'identical' if v else 'NOT identical'}" for k, v in identical.items()) + ".")
open(f"{out}/table.md", "w").write("\n".join(T) + "\n")
print("\n".join(T))
PY

if [[ -n "${COPY_TO:-}" ]]; then
  mkdir -p "$COPY_TO"
  cp "$out"/{table.md,summary.json,runs.csv,lockstep_identical.txt,machine.txt,io_test.json} "$COPY_TO"/ 2>/dev/null || true
  for d in "$out"/lockstep/*_a "$out"/realtime/openloop_r* "$out"/realtime/closedloop_r*; do
    [[ -d "$d" ]] || continue
    n="$(basename "$(dirname "$d")")_$(basename "$d")"
    [[ -f "$d/hil.json" ]] && cp "$d/hil.json" "$COPY_TO/$n.hil.json"
    [[ -f "$d/assess.json" ]] && cp "$d/assess.json" "$COPY_TO/$n.assess.json"
  done
  for p in "$out"/realtime/table51_*/r*.json; do
    [[ -f "$p" ]] && cp "$p" "$COPY_TO/realtime_$(basename "$(dirname "$p")")_$(basename "$p")"
  done
  log "small files copied to $COPY_TO"
fi
log "logs and reports: $out"
