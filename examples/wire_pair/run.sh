#!/usr/bin/env bash
# The twin (`hiltwin run`) and the controller (`hiltwin ecs`) as two processes on one wire, by
# hand: what `hiltwin hil --duration 2` does in one command. See README.md.
#
# Usage: run.sh [HILTWIN] [OUT_DIR]
#   HILTWIN  the hiltwin binary (default: `hiltwin` from PATH)
#   OUT_DIR  where each side's report, log and output go (default: a new folder under $TMPDIR)
# Prints both sides' output and exit codes; exits with the worse of the two codes, in the order
# `hiltwin hil` uses (0 < 3 FLAGGED < 4 ABORTED < 128+N stopped by signal N before any cycle
# was judged < 5 I/O < 2 bad input < 1 internal), so any side that did not PASS makes it
# non-zero.
set -euo pipefail

hiltwin=${1:-hiltwin}
out_dir=${2:-$(mktemp -d "${TMPDIR:-/tmp}/wire_pair.XXXXXX")}
wire="wire-pair-$$"  # one wire per run: two runs at once never share a segment
ecs_s=2              # the controller's run; it ends the pair
twin_s=$((ecs_s + 2))  # the twin runs longer (as hil's does), so the controller's finish stops it
wait_peer_s=30       # generous: on a loaded machine one side's real-time set-up can take a while
grace_s=3            # once one side ended, how long the other may take to notice (as hil)

if ! command -v "$hiltwin" >/dev/null; then
  echo "run.sh: no hiltwin binary '$hiltwin': pass its path, e.g. ./build/hiltwin" >&2
  exit 2
fi
mkdir -p "$out_dir"
echo "wire pair on wire:$wire, output in $out_dir"

"$hiltwin" run --io "wire:$wire" --duration "$twin_s" --wait-peer "$wait_peer_s" \
  --no-progress --report "$out_dir/twin.json" --log "$out_dir/twin.csv" \
  >"$out_dir/twin.out" 2>&1 &
twin_pid=$!
"$hiltwin" ecs --io "wire:$wire" --duration "$ecs_s" --wait-peer "$wait_peer_s" \
  --no-progress --report "$out_dir/ecs.json" --log "$out_dir/ecs.csv" \
  >"$out_dir/ecs.out" 2>&1 &
ecs_pid=$!
# Ctrl-C or a TERM stops both sides cleanly (each writes its report and leaves safe outputs).
trap 'kill -TERM "$twin_pid" "$ecs_pid" 2>/dev/null || true' INT TERM

# Until one side ends; then the other gets grace_s to follow before it is told to stop (a side
# that never got going leaves the other waiting in ready for up to wait_peer_s otherwise).
while kill -0 "$twin_pid" 2>/dev/null && kill -0 "$ecs_pid" 2>/dev/null; do sleep 0.1; done
for ((i = 0; i < grace_s * 10; i++)); do
  kill -0 "$twin_pid" 2>/dev/null || kill -0 "$ecs_pid" 2>/dev/null || break
  sleep 0.1
done
kill -TERM "$twin_pid" "$ecs_pid" 2>/dev/null || true

# A side's exit code; a wait that a trapped signal interrupts (128+n, the side still running)
# is repeated.
exit_code_of() {
  local rc
  while :; do
    rc=0
    wait "$1" || rc=$?
    if ((rc > 128)) && kill -0 "$1" 2>/dev/null; then continue; fi
    side_rc=$rc
    return 0
  done
}
exit_code_of "$twin_pid"
twin_rc=$side_rc
exit_code_of "$ecs_pid"
ecs_rc=$side_rc

echo "--- twin (hiltwin run)"
cat "$out_dir/twin.out"
echo "--- controller (hiltwin ecs)"
cat "$out_dir/ecs.out"
echo "---"
echo "twin exit $twin_rc"
echo "controller exit $ecs_rc"

# hil's order of badness: 0 < 3 < 4 < 129..159 (no verdict: stopped by a signal first) < 5 < 2
# < 1 < anything else (a crash).
rank() {
  case $1 in
    0) echo 0 ;; 3) echo 1 ;; 4) echo 2 ;; 129 | 1[3-5][0-9]) echo 3 ;; 5) echo 4 ;; 2) echo 5 ;;
    1) echo 6 ;; *) echo 7 ;;
  esac
}
if (($(rank "$twin_rc") >= $(rank "$ecs_rc"))); then worst=$twin_rc; else worst=$ecs_rc; fi
echo "pair exit $worst"
exit "$worst"
