#!/bin/sh
# Proves that a library checker (check_exports.sh, check_imports.sh) can fail: runs it on
# a deliberately broken library and requires exit status 1 and every expected complaint
# in its output.
#
# usage: expect_violations.sh CHECKER LIBRARY CHECKER_ARG EXPECTED_TEXT...
#   CHECKER_ARG: the checker's second argument (the public header folder of
#   check_exports.sh, the allow-list of check_imports.sh)
set -u
checker=$1 lib=$2 headers=$3
shift 3
out=$(sh "$checker" "$lib" "$headers" 2>&1)
rc=$?
printf '%s\n' "$out"
if [ "$rc" -ne 1 ]; then
    echo "expect_violations: checker exited $rc on a broken library, expected 1" >&2
    exit 1
fi
missing=0
for want in "$@"; do
    if ! printf '%s\n' "$out" | grep -qF -- "$want"; then
        echo "expect_violations: checker did not report: $want" >&2
        missing=$((missing + 1))
    fi
done
[ "$missing" -eq 0 ] || exit 1
echo "expect_violations: all $# expected violations reported"
