#!/usr/bin/env bash
# Wall time of the shipped campaign (campaigns/relbot_course.toml, 9 lockstep scenarios, 123 s
# simulated) with the tuned PID, --jobs 2 against its peer, the same campaign one scenario at a
# time (--jobs 1), alternating, five times each; prints the medians, the ratio and issue 38's
# target (<= 30 s with --jobs 2 on a 2-core machine). Wall clock: run it on a quiet machine.
# Usage: bench/campaign/campaign_speed.sh [build_dir] [repeats]
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
repeats=${2:-5}
exe="$build/hiltwin"
controller="$build/tests/controllers/tuned_pid.so"
[[ -x $exe && -f $controller ]] || {
  echo "build first: cmake --build $build --target hiltwin hiltwin_grading_controllers" >&2
  exit 2
}
campaign_s() {  # campaign_s JOBS: one run's wall time in seconds
  local start end
  start=$(date +%s.%N)
  "$exe" test "$root/campaigns/relbot_course.toml" --jobs "$1" --controller "lib:$controller" \
    >/dev/null || { echo "the campaign failed with --jobs $1" >&2; exit 1; }
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
two=(); one=()
for ((i = 0; i < repeats; ++i)); do
  two+=("$(campaign_s 2)")
  one+=("$(campaign_s 1)")
done
m2=$(printf '%s\n' "${two[@]}" | median)
m1=$(printf '%s\n' "${one[@]}" | median)
printf 'relbot_course, tuned PID, --jobs 2: median %.2f s of %d (runs: %s)\n' "$m2" "$repeats" "${two[*]}"
printf 'peer, --jobs 1 (one scenario at a time): median %.2f s (runs: %s)\n' "$m1" "${one[*]}"
printf 'ratio --jobs 1 / --jobs 2: %.2f; target <= 30 s with --jobs 2: %s\n' \
  "$(echo "$m1 / $m2" | bc -l)" "$(echo "$m2 <= 30" | bc -l | sed 's/1/met/; s/0/NOT met/')"
