#!/usr/bin/env bash
# The whole test suite, as CI runs it:
#   setup    tools/setup-debian.sh (installs missing Debian packages)
#   release  Release build in build/, warnings as errors, every CTest test
#   asan     Debug build in build-asan/ with ASan+UBSan (leaks too), every CTest test
#   tsan     Debug build in build-tsan/ with TSan, only the tests labelled "threads"
# Every stage runs even when an earlier one failed; the script prints each stage's wall
# time and status and exits non-zero if any stage failed.
#
# usage: bash tools/run-tests.sh [stage...]     (default: all four, in that order)
# env:   SINEW_JOBS (build parallelism, default: cores), SINEW_CTEST_JOBS (default 2)
set -uo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.." || exit 1
root=$(pwd)

jobs=${SINEW_JOBS:-$(nproc 2>/dev/null || echo 2)}
ctest_jobs=${SINEW_CTEST_JOBS:-2}

# Configure, build (keep going past errors), then test whatever did build, so one broken
# target does not hide the results of every other test. The stage fails if any step did.
# usage: build_and_test DIR "EXTRA CTEST ARGS" CMAKE_ARGS...
build_and_test() {
    local dir=$1 extra keep_going=() rc=0
    read -ra extra <<<"$2"
    shift 2
    cmake -S "$root" -B "$root/$dir" "$@" || return 1
    case $(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$root/$dir/CMakeCache.txt") in
    *Makefiles*) keep_going=(-- -k) ;;
    Ninja*) keep_going=(-- -k 0) ;;
    esac
    if ! cmake --build "$root/$dir" -j "$jobs" ${keep_going[@]+"${keep_going[@]}"}; then
        echo "=== run-tests: build in $dir FAILED; running the tests that did build ===" >&2
        rc=1
    fi
    ctest --test-dir "$root/$dir" --output-on-failure -j "$ctest_jobs" \
        ${extra[@]+"${extra[@]}"} || rc=1
    return "$rc"
}

stage_setup() {
    bash "$root/tools/setup-debian.sh"
}

stage_release() {
    build_and_test build "" \
        -DCMAKE_BUILD_TYPE=Release -DSINEW_WERROR=ON -DSINEW_SANITIZE=
}

stage_asan() {
    ASAN_OPTIONS=detect_leaks=1 \
        UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        build_and_test build-asan "" \
        -DCMAKE_BUILD_TYPE=Debug -DSINEW_WERROR=ON -DSINEW_SANITIZE=address,undefined
}

# Threading tests under TSan: tests/abi.cmake gives the label "threads" to every test
# whose name contains thread, determinism or pool. No such test is not a failure.
stage_tsan() {
    TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
        build_and_test build-tsan "-L threads --no-tests=ignore" \
        -DCMAKE_BUILD_TYPE=Debug -DSINEW_WERROR=ON -DSINEW_SANITIZE=thread
}

stages=("$@")
[ "${#stages[@]}" -gt 0 ] || stages=(setup release asan tsan)
for s in "${stages[@]}"; do
    case $s in
    setup | release | asan | tsan) ;;
    *) echo "run-tests: unknown stage '$s' (setup release asan tsan)" >&2; exit 2 ;;
    esac
done

summary=()
failed=0
for s in "${stages[@]}"; do
    echo "=== run-tests: stage $s ==="
    start=$(date +%s.%N)
    "stage_$s"
    rc=$?
    secs=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    if [ "$rc" -eq 0 ]; then status=ok; else status="FAILED (exit $rc)"; failed=1; fi
    echo "=== run-tests: stage $s: $status in ${secs} s ==="
    summary+=("$(printf '  %-8s %8s s  %s' "$s" "$secs" "$status")")
done

echo "=== run-tests: summary ==="
printf '%s\n' "${summary[@]}"
if [ "$failed" -ne 0 ]; then
    echo "run-tests: FAILED" >&2
    exit 1
fi
echo "run-tests: all stages passed"
