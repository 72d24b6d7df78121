#!/usr/bin/env bash
# Reproduces the thesis's figures on this machine, one row per figure of docs/RESULTS.md:
# open-loop twin vs reference (thesis 5.2-5.3, 5.6), the encoder link (Table 5.2), the twin's
# missed deadlines under the controller at 1/4/8/16 kHz (Table 5.1) and the closed loop (7.2).
#
# Real-time rows (--clock realtime) run RUNS times each, interleaved round by round; the table
# gives their median and range. Lockstep rows (--clock virtual: closed loop and open loop) run
# once per figure, and a second time to check that both runs are identical. The encoder-link
# row (io-test over mock) is deterministic and runs once.
# With the defaults this takes about 80 minutes (RUNS x (600 s + 4 x 60 s + 12 s) + overhead).
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
  table51.md         Table 5.1 in detail: misses, longest run, worst wake-up latency
  summary.json       every figure of every run, with median, min, max and N per figure
  runs.csv           one row per run and figure
  lockstep_identical.txt   whether the two lockstep runs of each figure are identical
  */openloop_*/rest_offset.csv   the twin's offset from the reference at each rest of the profile
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
  rest_offset "$d"
}

# rest_offset.csv: the openloop profile holds the wheels still (zero duty) from 12.3 s to 13.0 s
# of every 36 s repetition. At rest the twin's delay does not matter, so the twin's position
# minus the reference's there is the offset the run has built up (nothing corrects it in open
# loop). One row per repetition: the twin's own position (twin.csv) and the position the ECS
# measured through the encoder lines (ecs.csv, whole counts of 0.0785 mm) against the reference,
# and the twin's worst wake-up latency and misses since the previous rest.
rest_offset() {  # DIR
  python3 - "$1" <<'PY'
import sys
d = sys.argv[1]
T, A, B = 36.0, 12.4, 12.9
def rest(path, rate):
    out = {}
    with open(path) as f:
        h = f.readline().strip().split(","); ti = h.index("time_s"); wi = h.index("wheel_right_m")
        for line in f:
            p = line.split(",", wi + 1)
            t = float(p[ti])
            if A <= t % T <= B:
                out[round(t * rate)] = float(p[wi])
    return out
ref = rest(f"{d}/ref.csv", 4000)
def per_rep(vals, rate):
    rep = {}
    for k, v in vals.items():
        kr = k * 4000 // rate
        if kr in ref:
            s = rep.setdefault(int((k / rate) // T), [0.0, 0]); s[0] += v - ref[kr]; s[1] += 1
    return {k: 1e3 * s[0] / s[1] for k, s in rep.items()}
twin = per_rep(rest(f"{d}/twin.csv", 4000), 4000)
ecs = per_rep(rest(f"{d}/ecs.csv", 1000), 1000)
lat, miss = {}, {}
with open(f"{d}/twin.csv") as f:
    h = f.readline().strip().split(","); ti = h.index("time_s"); li = h.index("latency_us"); mi = h.index("missed")
    for line in f:
        p = line.split(",")
        k = int((float(p[ti]) - B) // T) + 1   # repetition whose rest this cycle precedes
        l = float(p[li])
        if l > lat.get(k, 0.0): lat[k] = l
        if p[mi].strip() not in ("0", "0.0"): miss[k] = miss.get(k, 0) + 1
with open(f"{d}/rest_offset.csv", "w") as f:
    f.write("repetition,rest_s,twin_minus_reference_mm,ecs_measured_minus_reference_mm,twin_worst_latency_ms_since_last_rest,twin_misses_since_last_rest\n")
    for k in sorted(twin):
        f.write(f"{k},{k * T + A:.1f}-{k * T + B:.1f},{twin[k]:.4f},{ecs.get(k, float('nan')):.4f},{lat.get(k, 0.0) / 1e3:.3f},{miss.get(k, 0)}\n")
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
for d in "$out"/lockstep/openloop_? "$out"/realtime/openloop_r*; do
  if [[ -f "$d/assess.json" && ! -f "$d/rest_offset.csv" ]]; then rest_offset "$d"; fi
done
python3 - "$out" <<'PY'
import csv, glob, hashlib, json, math, os, re, statistics, sys
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
def load1(p):  # the 1-minute load average when the run started (other work on the machine)
    return float(open(p).read().split()[0]) if os.path.exists(p) else float("nan")
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
        # the thesis's 5.6 threshold eps_t = 0.1854 m (K_e = 0.75), so the score compares like with like
        "eta_raw_thesis_eps": 0.75 * 0.1854 / math.hypot(0.75 * 0.1854, td["e_t"]),
        "twin_misses": h["twin"]["deadline_misses"], "twin_cycles": h["twin"]["cycles_run"],
        "twin_worst_latency_ms": h["twin"]["latency_ns"]["max"] / 1e6,
        "edges": h["ecs"]["encoder_lines"]["edges"],
        "edge_errors": sum(h["ecs"]["encoder_lines"][k] for k in ("illegal_transitions", "too_fast_edges", "resyncs")),
        "link_errors": h["link_errors"],
        "load1_at_start": load1(f"{d}/loadavg"),
    }
    rest = list(csv.DictReader(open(f"{d}/rest_offset.csv"))) if os.path.exists(f"{d}/rest_offset.csv") else []
    tw = [float(r["twin_minus_reference_mm"]) for r in rest]
    if tw:
        f["rest_offset_max_abs_mm"] = max(abs(o) for o in tw)
        f["rest_offset_last_mm"] = tw[-1]
        f["rest_offset_last_at"] = rest[-1]["rest_s"]
        # how much the offset moved between consecutive rests: the largest step
        f["rest_offset_biggest_step_mm"] = max((abs(tw[i] - tw[i - 1]) for i in range(1, len(tw))), default=0.0)
    return f
def closedloop_figs(d):
    h = load(f"{d}/hil.json")
    return {
        "max_mm": 1e3 * max(h["tracking_error_max_m"].values()),
        "max_left_mm": 1e3 * h["tracking_error_max_m"]["left"], "max_right_mm": 1e3 * h["tracking_error_max_m"]["right"],
        "rms_mm": 1e3 * h["tracking_error_rms_m"], "final_mm": 1e3 * h["final_error_m"],
        "twin_worst_latency_ms": h["twin"]["latency_ns"]["max"] / 1e6,
        "ecs_worst_latency_ms": h["ecs"]["latency_ns"]["max"] / 1e6,
        "load1_at_start": load1(f"{d}/loadavg"),
    }
def table51_figs(p):
    t = load(p)["twin"]
    return {"misses": t["deadline_misses"], "cycles": t["cycles_run"], "miss_pct": t["miss_pct"],
            "longest_run": t["max_consecutive_misses"], "worst_latency_ms": t["latency_ns"]["max"] / 1e6,
            "verdict": t["verdict"], "load1_at_start": load1(p[:-len(".json")] + ".loadavg")}

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
def fm(fmt, x):  # "%d" gets thousands separators
    return f"{int(round(x)):,}" if fmt == "%d" else fmt % x
def rt(fig, key, fmt, scale=1.0):
    s = stats(fig, key)
    if not s:
        return "not run"
    return f"{fm(fmt, scale * s['median'])} ({fm(fmt, scale * s['min'])}–{fm(fmt, scale * s['max'])}, N={s['n']})"
def ls(fig, key, fmt, scale=1.0):
    s = stats(fig, key)
    return fm(fmt, scale * s["median"]) if s else "not run"
T = []
T.append("| figure | real time: median (range, N runs) | lockstep (exact) | thesis |")
T.append("|---|---|---|---|")
T.append(f"| open-loop RMS position error, raw (§5.2) | {rt('openloop_realtime', 'e_raw_m', '%.3g', 1e3)} mm | {ls('openloop_lockstep', 'e_raw_m', '%.3g', 1e3)} mm | 0.922 mm |")
T.append(f"| open-loop RMS position error, delay-compensated (§5.3) | {rt('openloop_realtime', 'e_comp_m', '%.3g', 1e3)} mm | {ls('openloop_lockstep', 'e_comp_m', '%.3g', 1e3)} mm | 0.0971 mm |")
T.append(f"| open-loop delay, twin behind the reference (§5.3) | {rt('openloop_realtime', 'delay_ms', '%.3f')} ms | {ls('openloop_lockstep', 'delay_ms', '%.3f')} ms | 2 ms |")
T.append(f"| credibility η, raw, with the thesis's threshold ε_t = 0.1854 m (§5.6) | {rt('openloop_realtime', 'eta_raw_thesis_eps', '%.7f')} | {ls('openloop_lockstep', 'eta_raw_thesis_eps', '%.7f')} | 0.999978 |")
T.append(f"| credibility η, raw, as `hiltwin assess` scores it (ε_t = 0.05 × this run's range) | {rt('openloop_realtime', 'eta_raw', '%.10f')} | {ls('openloop_lockstep', 'eta_raw', '%.10f')} | — |")
T.append(f"| open-loop offset of the twin at rest, largest of the 17 rests (twin − reference) | {rt('openloop_realtime', 'rest_offset_max_abs_mm', '%.3f')} mm | {ls('openloop_lockstep', 'rest_offset_max_abs_mm', '%.3f')} mm | — |")
last_rest = next((f.get("rest_offset_last_at") for _, f in rows.get("openloop_lockstep", [])), None)
T.append(f"| the same at the last rest ({last_rest} s) | {rt('openloop_realtime', 'rest_offset_last_mm', '%.3f')} mm | {ls('openloop_lockstep', 'rest_offset_last_mm', '%.3f')} mm | — |")
T.append(f"| encoder edges decoded in the open-loop run; illegal / too fast / resyncs | {rt('openloop_realtime', 'edges', '%d')}; {rt('openloop_realtime', 'edge_errors', '%d')} | {ls('openloop_lockstep', 'edges', '%d')}; {ls('openloop_lockstep', 'edge_errors', '%d')} | — |")
if io:
    T.append(f"| encoder messages sent / received / missed (Table 5.2; deterministic, 1 run) | {io['encoder_messages_sent']:,} / {io['encoder_messages_received']:,} / {io['encoder_messages_missed']:,} | same | 720,000 / 720,000 / 0 |")
thesis51 = {1: "1 of 600,000 = 1.66e-4 %", 4: "9 of 2,400,000 = 3.75e-4 %", 8: "325,762 of 4,800,000 = 6.78 %", 16: "1,630,674 of 9,600,000 = 17.0 %"}
for khz in (1, 4, 8, 16):
    fig = f"table51_{khz}k"
    cyc = stats(fig, "cycles")
    cycs = f" of {int(cyc['median']):,}" if cyc else ""
    T.append(f"| twin's missed deadlines at {khz} kHz, under the controller (Table 5.1) | {rt(fig, 'misses', '%d')}{cycs} = {rt(fig, 'miss_pct', '%.3f')} % | — (no deadlines) | {thesis51[khz]} |")
T.append(f"| closed-loop max tracking error, per wheel (§7.2) | {rt('closedloop_realtime', 'max_mm', '%.2f')} mm | {ls('closedloop_lockstep', 'max_mm', '%.3f')} mm | below 3 mm |")
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

# Table 5.1 in detail, and the stalls behind the real-time rows
D = ["| run | misses | miss % | longest run of misses | twin's worst wake-up latency | thesis |", "|---|---|---|---|---|---|"]
for khz in (1, 4, 8, 16):
    fig = f"table51_{khz}k"
    D.append(f"| {khz} kHz | {rt(fig, 'misses', '%d')} | {rt(fig, 'miss_pct', '%.3f')} | {rt(fig, 'longest_run', '%d')} | {rt(fig, 'worst_latency_ms', '%.1f')} ms | {thesis51[khz]} |")
D.append(f"| open loop, 4 kHz, {int(stats('openloop_realtime', 'twin_cycles')['median']) if stats('openloop_realtime', 'twin_cycles') else 0:,} cycles | {rt('openloop_realtime', 'twin_misses', '%d')} | — | — | {rt('openloop_realtime', 'twin_worst_latency_ms', '%.1f')} ms | — |")
D.append(f"| closed loop, 4 kHz, 12 s | — | — | — | {rt('closedloop_realtime', 'twin_worst_latency_ms', '%.1f')} ms | — |")
open(f"{out}/table51.md", "w").write("\n".join(D) + "\n")
print()
print("\n".join(D))
PY

if [[ -n "${COPY_TO:-}" ]]; then
  mkdir -p "$COPY_TO"
  cp "$out"/{table.md,table51.md,summary.json,runs.csv,lockstep_identical.txt,machine.txt,io_test.json} "$COPY_TO"/ 2>/dev/null || true
  for d in "$out"/lockstep/*_a "$out"/realtime/openloop_r* "$out"/realtime/closedloop_r*; do
    [[ -d "$d" ]] || continue
    n="$(basename "$(dirname "$d")")_$(basename "$d")"
    [[ -f "$d/hil.json" ]] && cp "$d/hil.json" "$COPY_TO/$n.hil.json"
    [[ -f "$d/assess.json" ]] && cp "$d/assess.json" "$COPY_TO/$n.assess.json"
    [[ -f "$d/rest_offset.csv" ]] && cp "$d/rest_offset.csv" "$COPY_TO/$n.rest_offset.csv"
  done
  for p in "$out"/realtime/table51_*/r*.json; do
    [[ -f "$p" ]] && cp "$p" "$COPY_TO/realtime_$(basename "$(dirname "$p")")_$(basename "$p")"
  done
  log "small files copied to $COPY_TO"
fi
log "logs and reports: $out"
