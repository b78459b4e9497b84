#!/bin/sh
# Import check of the shared library (DESIGN.md §3): every undefined dynamic symbol of
# libsinew.so must be on a committed allow-list (the libc, libm, pthread, Embree and
# libccd functions the runtime really uses), so that a new dependency (stdio, a lock, an
# allocator, a library) cannot slip into the runtime unseen. A new import is a decision:
# add it to the list in the same commit, with the reason in the message.
#
# usage: check_imports.sh LIBRARY ALLOW_LIST [EXTRA_ALLOW_LIST...]
#   ALLOW_LIST: one symbol name per line (no @VERSION); '#' starts a comment; a line may
#   be a shell pattern (e.g. __asan_*) for the extra lists of sanitizer builds.
# exit:  0 clean, 1 import(s) not allowed (each printed on stderr), 2 usage or tool error.
set -u
LC_ALL=C
export LC_ALL

lib=${1:-}
allow=${2:-}
if [ -z "$lib" ] || [ -z "$allow" ] || [ ! -f "$lib" ] || [ ! -f "$allow" ]; then
    echo "usage: $0 LIBRARY ALLOW_LIST [EXTRA_ALLOW_LIST...] (got '$lib' '$allow')" >&2
    exit 2
fi
shift 2
for f in "$@"; do
    [ -f "$f" ] || { echo "check_imports: allow-list '$f' not found" >&2; exit 2; }
done
command -v nm >/dev/null 2>&1 || { echo "check_imports: 'nm' not found" >&2; exit 2; }

tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM

if ! nm -D --undefined-only "$lib" >"$tmp/nm.txt" 2>"$tmp/nm.err"; then
    echo "check_imports: nm failed on $lib:" >&2
    cat "$tmp/nm.err" >&2
    exit 2
fi
# "U name@VERSION" or "w name": the name, version dropped
awk 'NF >= 2 { n = $NF; sub(/@.*/, "", n); print n }' "$tmp/nm.txt" | sort -u >"$tmp/imports.txt"
count=$(wc -l <"$tmp/imports.txt" | tr -d ' ')
[ "$count" -gt 0 ] || { echo "check_imports: $lib imports nothing: not a real library?" >&2; exit 2; }

# the allowed names and patterns, comments and blanks dropped
cat "$allow" "$@" | sed 's/#.*//; s/[[:space:]]//g' | grep -v '^$' >"$tmp/allow.txt"

violations=0
while read -r name; do
    ok=0
    while read -r pat; do
        # shellcheck disable=SC2254 # the allow-list's lines are patterns on purpose
        case $name in $pat) ok=1; break ;; esac
    done <"$tmp/allow.txt"
    if [ "$ok" -eq 0 ]; then
        echo "IMPORT NOT ALLOWED in $lib: '$name' (not in $allow)" >&2
        violations=$((violations + 1))
    fi
done <"$tmp/imports.txt"

# Names on the list the library no longer imports: the list should shrink with it.
unused=$(grep -v '[*?[]' "$tmp/allow.txt" | sort -u | comm -23 - "$tmp/imports.txt" | tr '\n' ' ')
[ -z "$unused" ] || echo "check_imports: note: allowed but not imported (remove?): $unused"

if [ "$violations" -gt 0 ]; then
    echo "check_imports: $violations import(s) of $lib not on the allow-list" >&2
    exit 1
fi
echo "check_imports: OK: $count import(s) of $lib, all on the allow-list"
exit 0
