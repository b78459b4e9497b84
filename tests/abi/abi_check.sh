#!/bin/sh
# The exported ABI against the committed baseline (tests/abi/libsinew.abi), with abidiff
# (Debian abigail-tools). Only exported functions and the public headers' types count
# (--exported-interfaces-only, --headers-dir). Passes when nothing changed or when the
# changes are only additions (new functions or variables: the minor version's business);
# prints the report and a reminder to regenerate the baseline then. Fails
#   - on an incompatible change unless the SONAME was bumped (project VERSION major, hence
#     SOVERSION) since the baseline: abidiff's bit 8 (ABIDIFF_ABI_INCOMPATIBLE_CHANGE: a
#     function or variable removed), and also any function or variable whose type
#     changed (reported under bit 4, ABIDIFF_ABI_CHANGE, which libabigail leaves for a
#     human to judge: a public struct's size or member offsets, a signature). Harmless
#     changes (abidiff's default filter, e.g. a new enumerator) pass;
#   - on an abidiff error (bits 1 and 2).
# An intended change that this rule misreads (say a member appended to a struct_size-
# versioned def struct) is declared in tests/abi/libsinew.abignore, a libabigail
# suppression file (`man abidiff`, --suppressions), used when present.
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
    # Exported functions and the public types they reach only; source locations as file
    # names (no folders, so no checkout path): they let abidiff tell public types from
    # private ones (--headers-dir2), a baseline without them hides type changes.
    abidw --headers-dir "$headers" --drop-private-types --exported-interfaces-only \
        --no-corpus-path --no-comp-dir-path --short-locs --out-file "$baseline" "$lib" || exit 1
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

suppr=
[ -f "${baseline%.abi}.abignore" ] && suppr="--suppressions ${baseline%.abi}.abignore"
# shellcheck disable=SC2086 # $suppr is two words or none
report=$(abidiff --headers-dir2 "$headers" --drop-private-types --exported-interfaces-only \
    $suppr "$baseline" "$lib" 2>&1)
rc=$?
old_soname=$(sed -n 's/.*<abi-corpus [^>]*soname=.\([^"'"'"']*\).*/\1/p' "$baseline" | head -n 1)
new_soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')

if [ $((rc & 3)) -ne 0 ]; then
    printf '%s\n' "$report" >&2
    echo "abi_check: abidiff failed (exit $rc)" >&2
    exit 1
fi
if [ "$rc" -eq 0 ]; then
    echo "abi_check: ABI of $lib ($new_soname) unchanged against $baseline"
    exit 0
fi
printf '%s\n' "$report"
# Removed or changed functions and variables, symbols without debug info included, from
# the summary lines ("Functions changes summary: 0 Removed, 1 Changed (2 filtered out),
# 1 Added function"); the filtered-out count is not a change.
broken=$(printf '%s\n' "$report" | sed -n 's/^.*changes summary: *//p' |
    sed 's/([^)]*)//g' | tr ',' '\n' | awk '$2 == "Removed" || $2 == "Changed" { n += $1 }
    END { print n + 0 }')
if printf '%s\n' "$report" | grep -qiE 'SONAME changed|architecture changed'; then
    broken=$((broken + 1))
fi
if [ $((rc & 8)) -eq 0 ] && [ "$broken" -eq 0 ]; then
    echo "abi_check: compatible ABI change (additions only); regenerate the baseline" \
        "(target abi-baseline) when it is intended"
    exit 0
fi
if [ -n "$old_soname" ] && [ "$old_soname" != "$new_soname" ]; then
    echo "abi_check: incompatible ABI change with the SONAME bumped ($old_soname ->" \
        "$new_soname): allowed; regenerate the baseline (target abi-baseline)"
    exit 0
fi
echo "abi_check: INCOMPATIBLE ABI change (abidiff exit $rc, $broken removed or changed)" \
    "while the SONAME is still $new_soname: bump the project's major VERSION (SOVERSION)," \
    "or undo the change" >&2
exit 1
