#!/usr/bin/env bash
# Tracepoints compiled in but idle against compiled out: the run assembly's instructions per
# cycle (callgrind, bench/executive/callgrind_overhead.sh's `session` figure) in a normal build
# and in one configured with -DHILTWIN_WITH_LTTNG=OFF. Instructions, not seconds: repeatable on
# a busy machine.
# Usage: bench/trace/compiled_out.sh BUILD_WITH_LTTNG BUILD_WITHOUT_LTTNG
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
with=${1:?build dir with LTTng}; without=${2:?build dir configured with -DHILTWIN_WITH_LTTNG=OFF}
session() { bash "$here/../executive/callgrind_overhead.sh" "$1" | awk '/hiltwin session overhead/ { print $4 }'; }
in=$(session "$with"); out=$(session "$without")
echo "run assembly per cycle: tracepoints compiled in, idle: $in instructions; compiled out (peer): $out; difference $(( in - out )) ($(echo "scale=3; $in / $out" | bc)x)"
