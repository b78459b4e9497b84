#!/usr/bin/env bash
# What the README and the code's comments promise their readers: the README is a product
# page of at most 160 lines with no dates and no issue numbers; comments in runtime/,
# precompute/ and plugin_api/ say why, without issue numbers or "a -> b" measurement
# logs (the figures live in docs/notes/). Fails naming every line that breaks it.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root" || exit 1
fail=0
lines=$(wc -l <README.md)
if [ "$lines" -gt 160 ]; then
    echo "README.md: $lines lines (at most 160: details go to docs/)" >&2
    fail=1
fi
if grep -nE '\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b|[Ii]ssues? #?[0-9]+' README.md >&2; then
    echo "README.md: the lines above carry a date or an issue number (docs/notes/ keeps them)" >&2
    fail=1
fi
# issue numbers anywhere in the sources; "a -> b" figure lines (two numbers around an
# arrow) in their comments
srcs=$(git ls-files -- 'runtime/*.[ch]' 'precompute/*.[ch]' 'plugin_api/*.h')
# shellcheck disable=SC2086
if grep -nE '[Ii]ssues? [0-9]+' $srcs >&2; then
    echo "the lines above name an issue: say why instead" >&2
    fail=1
fi
# shellcheck disable=SC2086
if grep -nE '(^|[ (])[0-9][0-9.]*[GMk%]? ?(->|→) ?[0-9][0-9.]*' $srcs | grep -E '^\S+:[0-9]+:\s*(/?\*|//)' >&2; then
    echo "the comment lines above log a measurement (a -> b): docs/notes/ keeps figures" >&2
    fail=1
fi
[ "$fail" -eq 0 ] && echo "README and comments: no dates, issue numbers or measurement logs"
exit "$fail"
