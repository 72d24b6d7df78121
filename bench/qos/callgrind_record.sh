#!/bin/sh
# Instructions per QosMonitor::Record() (default rules, planned run) under callgrind: two
# runs with different cycle counts, so set-up (pattern generation, construction) cancels.
# Usage: callgrind_record.sh [path/to/hiltwin_bench_qos]
set -eu
bench=${1:-"$(dirname "$0")/hiltwin_bench_qos"}
n1=200000
n2=1200000
count() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bench" "$1" --once 2>&1 |
    sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
i1=$(count $n1)
i2=$(count $n2)
echo "instructions: n=$n1 -> $i1, n=$n2 -> $i2"
echo "instructions per Record(): $(( (i2 - i1) / (n2 - n1) ))"
