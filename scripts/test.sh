#!/usr/bin/env bash
# Builds and tests hiltwin in two tiers (docs/testing.md):
#   quick tier (no option, README's test command): the normal tree once, in build/, and every
#     default test in it (ctest -LE long): unit, integration, the wire and HiL pairs, LTTng,
#     tracefs, telemetry, FMUs, the gateware's lint, bitstreams and RTL co-simulation.
#   the matrix (--matrix; CI runs it after the quick tier): what only another build can find:
#     clang-tidy's function-size rule; ASan+UBSan (the default suite); ThreadSanitizer (label
#     concurrency: the tests that race threads or processes); arm64 cross-built and run under
#     qemu (labels unit, install, package); the bounded, seeded libFuzzer run of every parser.
#   --all: the quick tier, then the matrix.
#   --prebuild DIR: only the matrix's builds (ASan+UBSan, TSan, arm64, fuzz targets), two at a
#     time, each taken in that order by whichever builder is free, each leaving
#     DIR/<folder>.done or .failed. .ci/run starts it in the background at SCHED_IDLE before the
#     quick tier, so the matrix compiles on the CPU the quick tier's and the matrix's tests leave
#     idle; each matrix stage waits for its tree's mark (named by HILTWIN_PREBUILD_DIR), then
#     builds what is left.
# The opt-in label long (the hour-long soak, the 720,000-message and 12 s RTL runs) runs in no
# stage: ctest --test-dir build -L long. Each stage prints how long it built and tested, and a
# table of all stages closes the run.
# Usage: bash scripts/test.sh [--matrix | --all | --prebuild DIR] [--skip-arm64]
#   (the arm64 stage needs bash scripts/setup.sh --cross arm64)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)
quick=1
matrix=0
arm64=1
prebuild_dir=""
usage() { sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; }
while (($# > 0)); do
  case $1 in
    --matrix) quick=0; matrix=1 ;;
    --all) quick=1; matrix=1 ;;
    --prebuild)
      [[ -d ${2:-} ]] || { echo "test: --prebuild needs an existing folder for its marks" >&2; exit 2; }
      prebuild_dir=$(cd "$2" && pwd); shift ;;
    --skip-arm64) arm64=0 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "test: unknown argument '$1' (known: --matrix, --all, --prebuild DIR, --skip-arm64," \
            "--help)" >&2
       exit 2 ;;
  esac
  shift
done

# A stage that runs one label builds only the test executables that hold such tests
# (-DHILTWIN_TEST_LABELS, cmake/HiltwinTargets.cmake).
# Every tree keeps line tables only (-g1, scripts/build.sh). The ASan+UBSan build optimises
# its libraries at -Og: the sanitizers' documentation asks for -O1 or more for usable speed, and
# -Og is GCC's -O1 without the passes that obscure debugging; it compiles the libraries a third
# faster (two units: 125 -> 87 s) and the suite runs as before (docs/testing.md). Its tests' own
# code, where no test spends its time, compiles at -O0 (a unit of the app tests 45.0 -> 40.1 s,
# of the QoS tests 10.2 -> 7.7 s). The ThreadSanitizer build keeps -O2, as in the runs where
# its wall-clock pairs passed, and the arm64 build keeps -O2, what a Pi runs, and what keeps its
# emulated tests short. None of them builds the benchmarks or the gateware (bitstreams,
# Verilator model): the quick tier has them.
asan_flags=(-DCMAKE_C_FLAGS_RELWITHDEBINFO="-Og -g1 -DNDEBUG"
            -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-Og -g1 -DNDEBUG"
            -DHILTWIN_TEST_OPTIMIZATION="-O0;-g1")
no_extras=(-DHILTWIN_BUILD_BENCH=OFF -DHILTWIN_FPGA=OFF -DHILTWIN_FPGA_SIM=OFF)
# Each matrix tree's options, in one place: its stage and --prebuild configure it alike, so the
# stage's own build finds the prebuilt tree up to date.
asan_options=(-DHILTWIN_SANITIZE=ON "${no_extras[@]}" "${asan_flags[@]}"
              -DHILTWIN_TEST_SKIP_LABELS=long)
tsan_options=(-DHILTWIN_TSAN=ON -DHILTWIN_WITH_LTTNG=OFF "${no_extras[@]}"
              -DHILTWIN_TEST_LABELS=concurrency)
arm64_options=(--toolchain "$root/cmake/toolchains/aarch64-linux-gnu.cmake" "${no_extras[@]}"
               -DHILTWIN_TEST_LABELS=unit)

timings=()  # one "stage built tested" row per stage, printed at the end
flaky=()    # "stage: test" for each test that failed and passed when run again
tidy_pid=""
finish() {
  local status=$?
  [[ -z $tidy_pid ]] || kill "$tidy_pid" 2>/dev/null || true
  if ((${#timings[@]} > 0)); then
    echo "== test: stage times (s)"
    printf '%-44s %8s %8s\n' stage built tested
    printf '%-44s %8s %8s\n' "${timings[@]}"
  fi
  if ((${#flaky[@]} > 0)); then
    echo "== test: FLAKY, failed once and passed when run again (fix them; docs/testing.md):"
    printf '   %s\n' "${flaky[@]}"
  fi
  ((status == 0)) && echo "== test: every stage passed" || echo "== test: FAILED (exit $status)" >&2
}
trap finish EXIT

# The trees --prebuild builds, in the order the matrix uses them, by two builders side by side:
# each takes the next tree no one has taken yet (a mkdir claim, which only one can win). One
# builder alone left a core idle for a minute or two at the end of each tree (its last large
# unit, then its links: 400 idle CPU-seconds in a cold run). Two fixed chains (ASan then arm64,
# TSan then fuzz) kept both cores busy, but the arm64 tree then began only when the ASan tree
# was done, 7 minutes after the TSan chain could have taken it, and was the last to finish.
# Both builders run at SCHED_IDLE, so they share only what the tests leave.
prebuild_trees=(build-asan build-tsan build-arm64 build-fuzz)
prebuild_builders=2
# prebuild_tree FOLDER: builds one matrix tree and leaves DIR/FOLDER.done or .failed.
prebuild_tree() {
  local folder=$1 build
  case $folder in
    build-asan) build=(bash "$root/scripts/build.sh" "$root/$folder" "${asan_options[@]}") ;;
    build-tsan) build=(bash "$root/scripts/build.sh" "$root/$folder" "${tsan_options[@]}") ;;
    build-arm64) ((arm64)) || return 0
                 build=(bash "$root/scripts/build.sh" "$root/$folder" "${arm64_options[@]}") ;;
    build-fuzz) build=(bash "$root/scripts/fuzz.sh" --build-only) ;;
  esac
  # A failure is only marked: the stage's own build repeats the error where it is read.
  if "${build[@]}" >"$prebuild_dir/$folder.log" 2>&1; then
    touch "$prebuild_dir/$folder.done"
  else
    touch "$prebuild_dir/$folder.failed"
  fi
}
# prebuild_builder: builds, in the matrix's order, every tree it is the first to claim.
prebuild_builder() {
  local folder
  for folder in "${prebuild_trees[@]}"; do
    if mkdir "$prebuild_dir/$folder.claimed" 2>/dev/null; then prebuild_tree "$folder"; fi
  done
}
if [[ -n $prebuild_dir ]]; then
  builder_pids=()
  for ((builder = 0; builder < prebuild_builders; ++builder)); do
    prebuild_builder &
    builder_pids+=($!)
  done
  wait "${builder_pids[@]}"
  exit 0
fi

# build_stage DIR -- BUILD_OPTIONS...: configures and builds DIR, recording its build time.
# test_stage NAME DIR CTEST_OPTIONS...: runs ctest in DIR and records the row.
# wait_for_prebuild FOLDER: while `--prebuild` (HILTWIN_PREBUILD_DIR) still builds FOLDER, waits
# for it, so that two builds never share a tree; waiting, this stage leaves it every CPU.
wait_for_prebuild() {
  local marks=${HILTWIN_PREBUILD_DIR:-} folder=$1
  [[ -n $marks && -f $marks/pid && " ${prebuild_trees[*]} " == *" $folder "* ]] || return 0
  local pid said=0
  pid=$(<"$marks/pid")
  while [[ ! -e $marks/$folder.done && ! -e $marks/$folder.failed ]] && kill -0 "$pid" 2>/dev/null
  do
    ((said)) || echo "== waiting for the idle-priority build of $folder (scripts/test.sh --prebuild)"
    said=1
    sleep 1
  done
  # Its log says what it built; a failure is repeated by the stage's own build.
  [[ -e $marks/$folder.failed ]] && echo "== the idle-priority build of $folder failed" \
                                         "($marks/$folder.log); building it here" || true
}

build_stage() {
  local build_dir=$1; shift
  stage_start=$SECONDS
  wait_for_prebuild "$(basename "$build_dir")"
  echo "== building $build_dir"
  bash "$root/scripts/build.sh" "$build_dir" "$@"
  stage_built=$((SECONDS - stage_start))
}
# failure_digest DIR: each failed test of DIR's last ctest run, with its first failures (their
# place and message, lines cut at 300 characters), printed after ctest's summary: a reader who
# sees only the log's end (CI's summary keeps its last lines) then sees what failed, not only
# which test.
failure_digest() {
  local log=$1/Testing/Temporary/LastTest.log
  [[ -f $log ]] || return 0
  echo "== what failed (from $log):"
  awk '
    # A failure: its "file:line: Failure" and the three lines after it (gtest`s bare "Failed"
    # left out), six lines at most; without one (a crash, a timeout), the last three lines.
    function digest(   i, after, shown) {
      printf "%s\n", name
      after = 0
      shown = 0
      for (i = 1; i <= n && shown < 6; ++i) {
        if (out[i] ~ /: Failure$/) after = 4
        if (after > 0 && out[i] != "Failed") { printf "   %s\n", substr(out[i], 1, 300); ++shown }
        --after
      }
      for (i = (n > 3 ? n - 2 : 1); !shown && i <= n; ++i) printf "   %s\n", substr(out[i], 1, 300)
    }
    /^[0-9]+\/[0-9]+ Test: / { name = $0; sub(/^[0-9]+\/[0-9]+ Test: /, "", name); n = 0; next }
    /^Output:$/ { reading = 1; getline; next }
    /^<end of output>$/ { reading = 0; next }
    reading { out[++n] = $0; next }
    /^Test Failed/ && name != "" && ++failed <= 3 { digest() }
  ' "$log"
}
test_stage() {
  local name=$1 build_dir=$2; shift 2
  echo "== testing $name: ctest $*"
  local start=$SECONDS status=0 failed_tests test
  ctest --test-dir "$build_dir" --output-on-failure "$@" || status=$?
  if ((status != 0)); then
    # A failed test runs once more, alone: on a shared 2-core machine a wall-clock test can lose
    # to its neighbours. One that fails again fails the stage; one that passes is named as
    # flaky at the end of the run, with what it said the first time.
    failure_digest "$build_dir"
    local failed_log=$build_dir/Testing/Temporary/LastTestsFailed.log
    # ctest failed with no failed test (killed, no test to run): --rerun-failed would then run
    # every test again, so nothing is run again and the stage fails as ctest did.
    [[ -s $failed_log ]] || exit "$status"
    mapfile -t failed_tests < <(cut -d: -f2- "$failed_log")
    echo "== $name: running the ${#failed_tests[@]} failed test(s) once more, one at a time"
    status=0
    ctest --test-dir "$build_dir" --output-on-failure --rerun-failed -j 1 || status=$?
    if ((status != 0)); then
      failure_digest "$build_dir"
      exit "$status"
    fi
    for test in "${failed_tests[@]}"; do flaky+=("$name: $test"); done
  fi
  timings+=("$name" "$stage_built" "$((SECONDS - start))")
  echo "== $name: built in $stage_built s, tested in $((SECONDS - start)) s"
  stage_built=0
}

quick_tier() {
  build_stage "$root/build"
  test_stage "normal (quick tier)" "$root/build" -j "$jobs" -LE long
}

# clang-tidy only reads: it runs at SCHED_IDLE beside the other matrix stages, on the CPU their
# tests and links leave idle (a waking test preempts it at once), and the matrix collects its
# verdict at the end. Its row's time is its own, from its start to its end, overlapping the
# other stages' rows.
tidy_start() {
  # The quick tier's build: its compile commands, and the sources it generates, which clang-tidy
  # parses too. In --matrix alone it is built here when absent.
  stage_built=0
  [[ -f "$root/build/compile_commands.json" ]] || build_stage "$root/build"
  tidy_built=$stage_built
  tidy_log=$(mktemp "${TMPDIR:-/tmp}/hiltwin-tidy.XXXXXX")
  echo "== clang-tidy (function size) at idle priority beside the stages; its verdict comes last"
  (
    started=$SECONDS
    status=0
    chrt --idle 0 bash "$root/scripts/tidy.sh" "$root/build" || status=$?
    echo "$((SECONDS - started))" >"$tidy_log.seconds"
    exit "$status"
  ) >"$tidy_log" 2>&1 &
  tidy_pid=$!
}
tidy_finish() {
  local status=0
  wait "$tidy_pid" || status=$?
  tidy_pid=""
  cat "$tidy_log"
  timings+=("clang-tidy (function size, idle CPU)" "$tidy_built" "$(<"$tidy_log.seconds")")
  rm -f "$tidy_log" "$tidy_log.seconds"
  ((status == 0)) || exit "$status"
}

# ASan+UBSan: the whole default suite but the gateware, which the sanitizers cannot see into;
# the executables that hold only long tests (the soaks) are not built.
asan_stage() {
  build_stage "$root/build-asan" "${asan_options[@]}"
  test_stage "ASan+UBSan" "$root/build-asan" -j "$jobs" -LE long
}

# ThreadSanitizer, LTTng compiled out (its own synchronisation is opaque to TSan): the tests
# labelled concurrency. Each stops at its first report (TSAN_OPTIONS set by CTest, with
# tests/tsan.supp for the uninstrumented Debian libraries): a race fails it. The wall-clock ones
# (label rt) run after the rest, one at a time: instrumented, a process runs several times
# slower, and two real-time pairs side by side on two cores starve each other past the wire's
# 250 ms heartbeat (measured: 3 of 17 wire tests failed to start in 5 parallel repeats; none
# serially).
tsan_stage() {
  build_stage "$root/build-tsan" "${tsan_options[@]}"
  test_stage "TSan (concurrency)" "$root/build-tsan" -j "$jobs" -L concurrency -LE "^(long|rt)$"
  # HilCli.EitherSideMayStartFirst, once left out here, runs again: its failures under TSan were
  # the wire's start-up race, fixed in issue 34 (docs/testing.md, Flakiness). The open-loop
  # comparison with the reference runs in lockstep now (HilLockstep.OpenLoopTwinMatches...).
  test_stage "TSan (concurrency, rt, serial)" "$root/build-tsan" -j 1 -L concurrency -L "^rt$" \
    -LE long
}

# arm64, cross-built with Debian's toolchain and run under qemu-aarch64 (binfmt_misc runs the
# arm64 programs a test starts too): what can differ on arm64 (widths, atomics, alignment,
# packaging) is in the unit tests and the install and package tests. Not the wall-clock or
# two-process suites: an emulated CPU's timing tells nothing of a Pi's (docs/raspberry-pi.md).
arm64_stage() {
  if [[ ! -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ]]; then
    echo "test: qemu-aarch64 is not registered with binfmt_misc: run bash scripts/setup.sh" \
         "--cross arm64 (as root or with sudo), or skip this stage with --skip-arm64" >&2
    exit 1
  fi
  build_stage "$root/build-arm64" "${arm64_options[@]}"
  test_stage "arm64 under qemu (unit, install, package)" "$root/build-arm64" -j "$jobs" \
    -L "^(unit|install|package)$" -LE "^(long|rt|lttng|tracefs)$"
}

fuzz_stage() {
  local start=$SECONDS
  wait_for_prebuild build-fuzz
  bash "$root/scripts/fuzz.sh"
  timings+=("fuzz (libFuzzer, every parser)" "-" "$((SECONDS - start))")
}

((quick)) && quick_tier
if ((matrix)); then
  tidy_start
  asan_stage
  tsan_stage
  ((arm64)) && arm64_stage
  fuzz_stage
  tidy_finish
fi
