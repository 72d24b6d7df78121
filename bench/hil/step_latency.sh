#!/usr/bin/env bash
# End-to-end latency of the closed HiL loop (`hiltwin hil`, real time): from a setpoint step
# at the ECS to the first encoder count in the step's direction that the ECS reads back.
# Figures go to docs/BENCHMARKS.md.
#
# The ECS follows a generated setpoint profile: N steps of +-STEP m on both wheels, every
# INTERVAL s, starting at rest (0, +STEP, 0, +STEP, ...), large enough that the PID saturates.
# From the ECS's log (ECS time), per step and wheel:
#   first change  first ECS cycle whose count moved in the step's direction - the step's cycle.
#                 At rest the PID hunts across one count edge, so the wheel may sit a hair
#                 from the next count (or already be crossing it: a change within one ECS
#                 cycle of the step cannot be the answer, since the new duty is not on the wire
#                 before the next cycle; such samples are left out and listed).
#   new count     the same to the first count beyond every count of the 50 ms before the step:
#                 a full count of travel from a count edge, like the peer. Decomposed into
#     (a)         ECS cycles from the step until the duty on the wire changes (1 by design),
#     (c)         twin cycles from its first step with the new duty to its new count (twin
#                 time, twin.csv; the two logs start at different moments),
#     (b+d)       the rest: the twin's wait for its next sample, the encoder pulse (spread over
#                 the next twin period, its edge at the period's end) and the wait for the next
#                 ECS read (1 ms quantisation).
# Peer, same run: the model-only floor, `hiltwin run --clock virtual --io mock` with a duty
# step of the size the PID commanded, from rest at count 0 (a count edge): the time to count 1.
#
# Usage: bench/hil/step_latency.sh [options]       (see --help)
set -euo pipefail

usage() {
  cat <<EOF
Usage: bench/hil/step_latency.sh [--hiltwin PATH] [--twin-rate HZ] [--ecs-rate HZ]
                                 [--steps N] [--step-m M] [--interval-s S] [--log-dir DIR] [-v]
Measures the hil loop's latency from a setpoint step to the twin's encoder answer at the ECS.
  --hiltwin PATH    the binary (env HILTWIN; default: <repo>/build/hiltwin)
  --twin-rate HZ    twin rate (env TWIN_RATE; default 4000)
  --ecs-rate HZ     ECS rate (env ECS_RATE; default 1000)
  --steps N         setpoint steps (env STEPS; default 20)
  --step-m M        step size in metres of wheel travel (env STEP_M; default 0.05)
  --interval-s S    time between steps (env INTERVAL_S; default 0.5)
  --log-dir DIR     keep the hil logs and the floor run in DIR (default: a temporary folder)
  -v                print every step
EOF
}

die() { echo "step_latency: $*" >&2; exit 2; }

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
hiltwin=${HILTWIN:-$repo/build/hiltwin}
twin_rate=${TWIN_RATE:-4000}; ecs_rate=${ECS_RATE:-1000}
steps=${STEPS:-20}; step_m=${STEP_M:-0.05}; interval_s=${INTERVAL_S:-0.5}
log_dir=""; verbose=0
while [[ $# -gt 0 ]]; do
  case $1 in
    -h|--help) usage; exit 0 ;;
    -v) verbose=1; shift; continue ;;
    --hiltwin|--twin-rate|--ecs-rate|--steps|--step-m|--interval-s|--log-dir)
      [[ $# -ge 2 ]] || die "$1 needs a value" ;;
    *) usage >&2; die "unknown argument: $1" ;;
  esac
  case $1 in
    --hiltwin) hiltwin=$2 ;;
    --twin-rate) twin_rate=$2 ;;
    --ecs-rate) ecs_rate=$2 ;;
    --steps) steps=$2 ;;
    --step-m) step_m=$2 ;;
    --interval-s) interval_s=$2 ;;
    --log-dir) log_dir=$2 ;;
  esac
  shift 2
done
[[ -x "$hiltwin" ]] || die "no hiltwin binary at $hiltwin: build first (bash scripts/build.sh) or pass --hiltwin / HILTWIN"
command -v python3 >/dev/null || die "python3 missing"
[[ $steps =~ ^[1-9][0-9]*$ ]] || die "--steps must be a positive whole number, got $steps"
for v in "$twin_rate" "$ecs_rate" "$step_m" "$interval_s"; do
  [[ $v =~ ^[0-9]*\.?[0-9]+$ ]] && [[ ! $v =~ ^0*\.?0*$ ]] || die "rates, step size and interval must be positive numbers, got $v"
done

tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
work=${log_dir:-$tmp}
mkdir -p "$work" || die "cannot create $work"

# Setpoints: rest, then levels 0, +STEP, 0, ... switching every INTERVAL (a repeated time is a
# step), held for one more INTERVAL after the last step.
python3 - "$steps" "$step_m" "$interval_s" >"$work/setpoints.csv" <<'PY'
import sys
n, step, dt = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
print("time,left_m,right_m\n0,0,0")
level = 0.0
for i in range(1, n + 1):
    t = round(i * dt, 9)  # 0.3, not 0.30000000000000004: the step lands on its ECS cycle
    new = step if level == 0.0 else 0.0
    print(f"{t!r},{level!r},{level!r}\n{t!r},{new!r},{new!r}")
    level = new
print(f"{round((n + 1) * dt, 9)!r},{level!r},{level!r}")
PY
duration=$(python3 -c "print(repr(round(($steps + 1) * $interval_s, 9)))")

echo "hil step latency: $steps steps of +-$step_m m every $interval_s s, twin $twin_rate Hz, ECS $ecs_rate Hz (hiltwin hil, real time, ${duration} s)"
set +e
"$hiltwin" hil --twin-rate "$twin_rate" --ecs-rate "$ecs_rate" --setpoint "$work/setpoints.csv" \
  --duration "$duration" --log-dir "$work/hil" --no-progress >"$work/hil.out" 2>&1
code=$?
set -e
# 3 = FLAGGED: a deadline rule was violated (hypervisor stalls); the logs are complete.
if [[ $code -ne 0 && $code -ne 3 ]]; then
  cat "$work/hil.out" >&2
  die "hiltwin hil failed with exit code $code"
fi

# Peer: the model alone, from rest, a duty step to the size the PID commanded after the steps.
duty=$(python3 - "$work/hil/ecs.csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
after = [abs(float(rows[k + 1]["duty_left"])) for k in range(1, len(rows) - 1)
         if rows[k]["setpoint_left_m"] != rows[k - 1]["setpoint_left_m"]]
if not after:
    sys.exit("step_latency: no setpoint step found in ecs.csv")
print(repr(statistics.median_low(after)))
PY
)
printf 'time,left,right\n0,0,0\n0.1,0,0\n0.1,%s,%s\n0.5,%s,%s\n' "$duty" "$duty" "$duty" "$duty" >"$work/duty_step.csv"
"$hiltwin" run --clock virtual --io mock --input "$work/duty_step.csv" --input-rate "$ecs_rate" \
  --rate "$twin_rate" --duration 0.5 --no-progress --log "$work/floor.csv" >"$work/floor.out" 2>&1 ||
  { cat "$work/floor.out" >&2; die "the floor run (hiltwin run --clock virtual) failed"; }

python3 - "$work" "$ecs_rate" "$twin_rate" "$interval_s" "$steps" "$verbose" <<'PY'
import csv, json, math, statistics, sys
work, ecs_hz, twin_hz, interval_s, n_steps, verbose = sys.argv[1:]
ecs_dt, twin_dt, interval_s = 1 / float(ecs_hz), 1 / float(twin_hz), float(interval_s)
rest_s = min(0.05, interval_s / 2)  # the window before a step that shows the count range at rest
ecs = list(csv.DictReader(open(f"{work}/hil/ecs.csv")))
twin = list(csv.DictReader(open(f"{work}/hil/twin.csv")))
ref = list(csv.DictReader(open(f"{work}/floor.csv")))
f = lambda row, col: float(row[col])

def first(rows, start, test):
    return next((i for i in range(start, len(rows)) if test(rows[i])), None)

def beyond_rest(rows, k, n_rest, col, sign):
    """First row after k whose count is beyond every count of the n_rest rows up to k."""
    rest = [sign * f(r, col) for r in rows[max(0, k - n_rest):k + 1]]
    return first(rows, k + 1, lambda r: sign * f(r, col) > max(rest))

# Floor: duty step at 0.1 s; a log row's time is the end of its step, when its count is known.
on = first(ref, 0, lambda r: f(r, "duty_left") != 0)
moved = first(ref, on, lambda r: f(r, "enc_left") != 0) if on is not None else None
if moved is None:
    sys.exit("step_latency: the floor run's wheel never reached one count")
floor_ms = (f(ref[moved], "time_s") - 0.1) * 1e3

steps = [k for k in range(1, len(ecs)) if ecs[k]["setpoint_left_m"] != ecs[k - 1]["setpoint_left_m"]]
if len(steps) != int(n_steps):
    sys.exit(f"step_latency: found {len(steps)} setpoint steps in ecs.csv, expected {n_steps}")

first_ms, full_ms, a_cycles, twin_ms, rest_ms, excluded, stalled = [], [], [], [], [], [], []
offset_s = None  # twin log time - ECS log time of the same moment (the logs start apart)
for i, k in enumerate(steps):
    t0 = f(ecs[k], "time_s")
    for wheel in ("left", "right"):
        sp, enc, duty = f"setpoint_{wheel}_m", f"enc_{wheel}", f"duty_{wheel}"
        sign = 1 if f(ecs[k], sp) > f(ecs[k - 1], sp) else -1
        d = first(ecs, k, lambda r: r[duty] != ecs[k][duty])
        j = first(ecs, k + 1, lambda r: sign * (f(r, enc) - f(ecs[k], enc)) > 0)
        n = beyond_rest(ecs, k, round(rest_s / ecs_dt), enc, sign)
        if d is None or j is None or n is None:
            sys.exit(f"step_latency: step {i + 1} ({wheel}): no answer in ecs.csv")
        a_cycles.append(d - k)
        if j - k < 2:  # moved before the new duty could have reached the twin and come back
            excluded.append(f"{i + 1} {wheel}")
        else:
            first_ms.append((f(ecs[j], "time_s") - t0) * 1e3)
        full_ms.append((f(ecs[n], "time_s") - t0) * 1e3)
        if any(f(r, "missed") for r in ecs[k:n + 1]):
            stalled.append(f"{i + 1} {wheel} (ECS)")
        # The twin's share: its first step with the new duty (the reader saturates at 2047/2048,
        # the ECS logs -2048/2048: compare within 2 PWM steps), then its first count beyond rest.
        out_s = f(ecs[d], "time_s")
        new_duty = lambda r: abs(f(r, duty) - f(ecs[d], duty)) <= 2 / 2048
        since = 0 if offset_s is None else first(twin, 0, lambda r: f(r, "time_s") >= out_s + offset_s - interval_s / 2)
        r = first(twin, since, new_duty) if since is not None else None
        m = beyond_rest(twin, r - 1, round(rest_s / twin_dt), enc, sign) if r else None
        if r is None or m is None:
            print(f"  step {i + 1} {wheel}: not found in twin.csv", file=sys.stderr)
            continue
        if offset_s is None:
            offset_s = f(twin[r], "time_s") - twin_dt - out_s
        twin_ms.append((m - r + 1) * twin_dt * 1e3)
        rest_ms.append(full_ms[-1] - (d - k) * ecs_dt * 1e3 - twin_ms[-1])
        if any(f(x, "missed") for x in twin[r:m + 1]):
            stalled.append(f"{i + 1} {wheel} (twin)")
        if verbose == "1":
            print(f"  step {i + 1:2} {wheel:5} t={t0:6.3f} s {sign:+d}: first count "
                  f"{(f(ecs[j], 'time_s') - t0) * 1e3:5.2f} ms, new count {full_ms[-1]:5.2f} ms = (a) {d - k} "
                  f"ECS cycle + (c) twin {twin_ms[-1]:.2f} ms + (b+d) {rest_ms[-1]:.2f} ms")

def pct(xs, p):  # nearest rank
    xs = sorted(xs)
    return xs[max(0, math.ceil(p / 100 * len(xs)) - 1)]

def line(xs):
    return (f"min {min(xs):5.2f}  median {statistics.median(xs):5.2f}  p90 {pct(xs, 90):5.2f}  "
            f"max {max(xs):5.2f} ms  (n={len(xs)})")

if not first_ms:
    sys.exit("step_latency: every step's first change came within one ECS cycle")
print(f"  step -> first count change in its direction:  {line(first_ms)}")
print(f"  step -> first count beyond the rest range:    {line(full_ms)}")
print(f"    (a) step -> new duty on the wire: {min(a_cycles)}..{max(a_cycles)} ECS cycles")
if twin_ms:
    print(f"    (c) twin: new duty -> new count:          {line(twin_ms)}")
    print(f"    (b+d) twin pickup + pulse + ECS read:     {line(rest_ms)}")
print(f"  peer: model-only floor, duty {abs(f(ref[on], 'duty_left')):.4f} from rest on a count edge "
      f"(hiltwin run --clock virtual --io mock, {twin_hz} Hz): {floor_ms:.2f} ms to the first count")
print(f"  ratio median / floor: {statistics.median(first_ms) / floor_ms:.2f} (first change), "
      f"{statistics.median(full_ms) / floor_ms:.2f} (beyond rest)")
io_us = [f(r, "compute_us") + f(r, "io_us") for r in ecs]
print(f"  for context: the ECS's own compute + I/O per cycle, median {statistics.median(io_us):.2f} us")
if excluded:
    print(f"  first change left out (moved within one ECS cycle, creeping at rest): {', '.join(excluded)}")
if stalled:
    print(f"  a deadline miss inside the step's window: {', '.join(stalled)}")
for side in ("twin", "ecs"):
    rep = json.load(open(f"{work}/hil/{side}.json"))
    print(f"  {side}: {rep['verdict']}, {rep['deadline_misses']} misses ({rep['miss_pct']:.3f} %), "
          f"longest run {rep['max_consecutive_misses']}")
PY
