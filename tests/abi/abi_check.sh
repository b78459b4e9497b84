#!/bin/sh
# The exported ABI against the committed baseline (tests/abi/libsinew.abi), with abidiff
# (Debian abigail-tools). Only the public headers' types count (--headers-dir). Fails
#   - on an incompatible change (abidiff bit 8, ABIDIFF_ABI_INCOMPATIBLE_CHANGE: a symbol
#     removed, a public struct's layout or a function's signature changed) unless the
#     SONAME was bumped (project VERSION major, hence SOVERSION) since the baseline;
#   - on an abidiff error (bits 1 and 2).
# Passes on compatible changes (bit 4 alone, e.g. a new exported function), printing the
# report and a reminder to regenerate the baseline.
#
# The baseline is regenerated from a Release build with the CMake target abi-baseline:
#   cmake --build build --target abi-baseline     (runs abi_check.sh --write)
# after an intended change (a new function, or a major version bump), and committed.
#
# usage: abi_check.sh BASELINE LIBRARY HEADERS_DIR
#        abi_check.sh --write BASELINE LIBRARY HEADERS_DIR
set -u

write=0
if [ "${1:-}" = --write ]; then
    write=1
    shift
fi
[ $# -eq 3 ] || {
    echo "usage: abi_check.sh [--write] BASELINE LIBRARY HEADERS_DIR" >&2
    exit 2
}
baseline=$1 lib=$2 headers=$3

for t in abidw abidiff; do
    if ! command -v $t >/dev/null 2>&1; then
        echo "abi_check: $t not found (Debian abigail-tools, tools/setup-debian.sh): skipped" >&2
        exit 77
    fi
done

if [ $write -eq 1 ]; then
    # Exported functions and the public types they reach only; no source locations, and
    # the translation units' paths relative to the source root (HEADERS_DIR/../..): the
    # file changes only when the ABI does, wherever the tree is checked out.
    root=$(cd "$headers/../.." && pwd)
    abidw --headers-dir "$headers" --drop-private-types --exported-interfaces-only \
        --no-corpus-path --no-comp-dir-path --no-show-locs "$lib" >"$baseline.tmp" || {
        rm -f "$baseline.tmp"
        exit 1
    }
    sed "s|path='$root/|path='|" "$baseline.tmp" >"$baseline" && rm -f "$baseline.tmp" || exit 1
    echo "abi_check: wrote $baseline from $lib"
    exit 0
fi

[ -f "$baseline" ] || {
    echo "abi_check: no baseline $baseline (cmake --build <dir> --target abi-baseline)" >&2
    exit 1
}
if ! readelf -S "$lib" | grep -q '\.debug_info'; then
    echo "abi_check: $lib has no DWARF: abidiff would see symbols only" >&2
    exit 1
fi

report=$(abidiff --headers-dir2 "$headers" --drop-private-types --exported-interfaces-only \
    "$baseline" "$lib" 2>&1)
rc=$?
old_soname=$(sed -n 's/.*<abi-corpus [^>]*soname=.\([^"'"'"']*\).*/\1/p' "$baseline" | head -n 1)
new_soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')

if [ $((rc & 3)) -ne 0 ]; then
    printf '%s\n' "$report" >&2
    echo "abi_check: abidiff failed (exit $rc)" >&2
    exit 1
fi
if [ $((rc & 8)) -ne 0 ]; then
    printf '%s\n' "$report"
    if [ -n "$old_soname" ] && [ "$old_soname" != "$new_soname" ]; then
        echo "abi_check: incompatible ABI change with the SONAME bumped ($old_soname ->" \
            "$new_soname): allowed; regenerate the baseline (target abi-baseline)"
        exit 0
    fi
    echo "abi_check: INCOMPATIBLE ABI change while the SONAME is still $new_soname: bump the" \
        "project's major VERSION (SOVERSION) or undo the change" >&2
    exit 1
fi
if [ $((rc & 4)) -ne 0 ]; then
    printf '%s\n' "$report"
    echo "abi_check: compatible ABI change (e.g. an added function); regenerate the baseline" \
        "(target abi-baseline) when it is intended"
    exit 0
fi
echo "abi_check: ABI of $lib ($new_soname) unchanged against $baseline"
exit 0
