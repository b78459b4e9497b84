#!/usr/bin/env bash
# The whole test suite, as CI runs it:
#   setup    tools/setup-debian.sh (installs missing Debian packages)
#   format   clang-format --dry-run -Werror (the repo's .clang-format, Debian 12's
#            clang-format 14) over every git-tracked *.c, *.h and *.cpp file; fails naming
#            the files that are not formatted (fix: clang-format -i FILE)
#   release  Release build in build/, warnings as errors, every CTest test
#   asan     Debug build (-O1) in build-asan/ with ASan+UBSan (leaks too), every CTest test
#            but those that cannot or need not run instrumented (the Blender add-on, the
#            Slurm farm: tests/CMakeLists.txt says why)
#   tsan     Debug build (-O1) in build-tsan/ with TSan, only the tests labelled "threads"
# Every stage runs even when an earlier one failed; the script prints each stage's wall
# time and status and exits non-zero if any stage failed.
#
# usage: bash tools/run-tests.sh [stage...]     (default: all five, in that order)
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

# Checks, changes nothing. One batched run first; when it fails, each file on its own, so
# that the failures are named file by file.
stage_format() {
    if ! command -v clang-format >/dev/null 2>&1; then
        echo "run-tests: clang-format not found (tools/setup-debian.sh installs it)" >&2
        return 1
    fi
    local files=() bad=() f out
    mapfile -d '' files < <(git -C "$root" ls-files -z -- '*.c' '*.h' '*.cpp')
    if [ "${#files[@]}" -eq 0 ]; then
        echo "run-tests: no git-tracked C/C++ files found (not a git checkout?)" >&2
        return 1
    fi
    clang-format --version
    local present=()
    for f in "${files[@]}"; do
        [ -f "$root/$f" ] && present+=("$f") # not those deleted in the working tree
    done
    if (cd "$root" && clang-format --style=file --dry-run -Werror "${present[@]}" 2>/dev/null); then
        echo "run-tests: format: ${#present[@]} files checked, all formatted"
        return 0
    fi
    for f in "${present[@]}"; do
        if ! out=$(clang-format --style=file --dry-run -Werror "$root/$f" 2>&1); then
            bad+=("$f")
            # Not a formatting difference (a bad .clang-format, a crash): show it.
            grep -q 'clang-format-violations' <<<"$out" || printf '%s\n' "$out" >&2
        fi
    done
    echo "run-tests: format: ${#present[@]} files checked, ${#bad[@]} not formatted"
    [ "${#bad[@]}" -eq 0 ] && return 0
    echo "run-tests: not formatted as .clang-format says (fix with clang-format -i FILE):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    return 1
}

stage_release() {
    build_and_test build "" \
        -DCMAKE_BUILD_TYPE=Release -DSINEW_WERROR=ON -DSINEW_SANITIZE=
}

# The sanitizer builds are Debug builds at -O1, the level the ASan and TSan manuals
# recommend for usable speed: at -O0 every small inline kernel (vec3.h, penalty.h, the
# dense dot products) stays a call and the suite spends its time in call overhead.
sanitizer_flags=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_C_FLAGS_DEBUG=-g -O1"
    "-DCMAKE_CXX_FLAGS_DEBUG=-g -O1" -DSINEW_WERROR=ON)

stage_asan() {
    ASAN_OPTIONS=detect_leaks=1 \
        UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        build_and_test build-asan "" \
        "${sanitizer_flags[@]}" -DSINEW_SANITIZE=address,undefined
}

# Threading tests under TSan: tests/abi.cmake gives the label "threads" to every test
# whose name contains thread, determinism or pool. No such test is not a failure.
stage_tsan() {
    TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
        build_and_test build-tsan "-L threads --no-tests=ignore" \
        "${sanitizer_flags[@]}" -DSINEW_SANITIZE=thread
}

stages=("$@")
[ "${#stages[@]}" -gt 0 ] || stages=(setup format release asan tsan)
for s in "${stages[@]}"; do
    case $s in
    setup | format | release | asan | tsan) ;;
    *) echo "run-tests: unknown stage '$s' (setup format release asan tsan)" >&2; exit 2 ;;
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
