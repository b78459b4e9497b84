#!/usr/bin/env bash
# Long fuzzing runs of every libFuzzer harness of tests/fuzz (the CTest tests run each
# for a few seconds only). Configures build/ when it has no cache, builds the harnesses
# (targets <name>_harness; clang with libFuzzer), runs each for SECONDS on a scratch copy
# of its seed corpus (the seeds stay untouched), and prints per harness the executions,
# executions per second, crashes, slow inputs (one run over 10 s), and the seconds 1e7
# executions would take. Exits non-zero
# when any harness crashed (ASan, UBSan, a leak, a broken reader promise = abort) or did
# not run; the crashing inputs are kept in BUILD/fuzz-artifacts/<name>/.
#
# usage: bash tools/scripts/run-fuzz.sh [SECONDS_PER_HARNESS] [HARNESS...]   (default 60, all)
# env:   SINEW_FUZZ_BUILD (build folder, default build), SINEW_JOBS (default 2),
#        SINEW_FUZZ_KEEP=1 keeps the scratch corpora (their paths are printed)
set -uo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/../.." || exit 1
root=$(pwd)
secs=${1:-60}
[ $# -gt 0 ] && shift
case $secs in
'' | *[!0-9]*)
    echo "run-fuzz: SECONDS_PER_HARNESS must be a positive integer, got '$secs'" >&2
    exit 2
    ;;
esac
build=${SINEW_FUZZ_BUILD:-$root/build}
jobs=${SINEW_JOBS:-2}

if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release || exit 1
fi
list=$build/tests/fuzz_harnesses.txt
if [ ! -s "$list" ]; then
    echo "run-fuzz: no harness in $list (no clang with libFuzzer at configure time?)" >&2
    exit 1
fi

names=()
while read -r name _; do
    if [ $# -eq 0 ]; then
        names+=("$name")
    else
        for want in "$@"; do [ "$want" = "$name" ] && names+=("$name"); done
    fi
done <"$list"
if [ "${#names[@]}" -eq 0 ]; then
    echo "run-fuzz: none of '$*' is a harness of $list" >&2
    exit 2
fi
targets=()
for name in "${names[@]}"; do targets+=(--target "${name}_harness"); done
cmake --build "$build" -j "$jobs" "${targets[@]}" || exit 1

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
scratch_root=$(mktemp -d "${TMPDIR:-/tmp}/sinew-fuzz.XXXXXX")
[ "${SINEW_FUZZ_KEEP:-0}" = 1 ] || trap 'rm -rf "$scratch_root"' EXIT

failed=0
report=()
for name in "${names[@]}"; do
    read -r _ exe corpus < <(grep "^$name " "$list")
    dir=$scratch_root/$name
    mkdir -p "$dir/corpus" "$dir/artifacts"
    cp -r "$corpus/." "$dir/corpus/"
    echo "=== run-fuzz: $name for ${secs}s on a copy of $corpus"
    "$exe" -max_total_time="$secs" -max_len=65536 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$dir/artifacts/" "$dir/corpus" >"$dir/log" 2>&1
    rc=$?
    # libFuzzer's final statistics; "Done N runs in S second(s)" is its "#N DONE" line
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log" | tail -n 1)
    [ -n "$execs" ] || execs=$(sed -n 's/^#\([0-9]*\)[[:space:]]*DONE.*/\1/p' "$dir/log" | tail -n 1)
    ran=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$dir/log" | tail -n 1)
    [ -n "$ran" ] && [ "$ran" -gt 0 ] || ran=$secs
    # crash-, leak-, timeout-, oom- inputs fail the run; slow-unit- inputs (one input took
    # longer than libFuzzer's -report_slow_units, 10 s) are kept and counted, not failed
    crashes=$(find "$dir/artifacts" -type f ! -name 'slow-unit-*' | wc -l)
    slow=$(find "$dir/artifacts" -type f -name 'slow-unit-*' | wc -l)
    if [ "$slow" -gt 0 ]; then
        mkdir -p "$build/fuzz-artifacts/$name"
        cp "$dir/artifacts/"slow-unit-* "$build/fuzz-artifacts/$name/"
        echo "=== run-fuzz: $name: $slow slow input(s) kept in $build/fuzz-artifacts/$name" >&2
    fi
    if [ "$rc" -ne 0 ] || [ "$crashes" -gt 0 ] || [ -z "$execs" ]; then
        failed=1
        [ "$crashes" -gt 0 ] || crashes=1
        keep=$build/fuzz-artifacts/$name
        mkdir -p "$keep"
        cp "$dir/log" "$keep/log"
        cp "$dir/artifacts/"* "$keep/" 2>/dev/null
        echo "=== run-fuzz: $name FAILED (exit $rc); log and inputs in $keep" >&2
        grep -E 'ERROR|runtime error|SUMMARY|deadly|Test unit written' "$dir/log" | head -n 8 >&2
    fi
    execs=${execs:-0}
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$dir/log" | tail -n 1)
    [ -n "$rate" ] && [ "$rate" -gt 0 ] || rate=$((execs / ran))
    if [ "$rate" -gt 0 ]; then need=$(((10000000 + rate - 1) / rate)); else need=-; fi
    report+=("$(printf '%-16s %8s %12s %10s %8s %5s %10s' "$name" "$ran" "$execs" "$rate" \
        "$crashes" "$slow" "$need")")
done

printf '%-16s %8s %12s %10s %8s %5s %10s\n' harness seconds executions execs/s crashes slow \
    's_for_1e7'
printf '%s\n' "${report[@]}"
[ "${SINEW_FUZZ_KEEP:-0}" = 1 ] && echo "scratch corpora kept in $scratch_root"
exit "$failed"
