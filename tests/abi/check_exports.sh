#!/bin/sh
# ABI check of the shared library (DESIGN.md §3): only sinew_ functions are exported,
# exactly the SINEW_API functions the public headers declare, no writable data that two
# hosts could fight over, and the SONAME carries the header's major version.
#
# usage: check_exports.sh LIBRARY PUBLIC_HEADER_DIR
# exit:  0 clean, 1 ABI violation(s) (each printed on stderr), 2 usage or tool error.
set -u
LC_ALL=C
export LC_ALL

lib=${1:-}
headers=${2:-}
if [ -z "$lib" ] || [ -z "$headers" ] || [ ! -f "$lib" ] || [ ! -d "$headers" ]; then
    echo "usage: $0 LIBRARY PUBLIC_HEADER_DIR (got '$lib' '$headers')" >&2
    exit 2
fi
for tool in nm readelf perl; do
    command -v "$tool" >/dev/null 2>&1 || { echo "check_exports: '$tool' not found" >&2; exit 2; }
done

violations=0
violation() {
    echo "ABI VIOLATION in $lib: $*" >&2
    violations=$((violations + 1))
}

tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM

# --- exported symbols as "TYPE NAME", any @VERSION suffix dropped ---
if ! nm -D --defined-only "$lib" >"$tmp/nm.txt" 2>"$tmp/nm.err"; then
    echo "check_exports: nm failed on $lib:" >&2
    cat "$tmp/nm.err" >&2
    exit 2
fi
awk 'NF >= 3 { sub(/@.*/, "", $3); print $2, $3 }' "$tmp/nm.txt" | sort -u -k2 >"$tmp/exports.txt"
awk '{ print $2 }' "$tmp/exports.txt" | sort -u >"$tmp/names.txt"

count=$(wc -l <"$tmp/names.txt" | tr -d ' ')
[ "$count" -gt 0 ] || violation "exports no symbols at all"
grep -qx 'sinew_version' "$tmp/names.txt" || violation "does not export sinew_version"

# Anything without the prefix leaked out of the version script / visibility settings.
while read -r type name; do
    case $name in
    sinew_*) ;;
    *) violation "exported symbol '$name' (type $type) is not prefixed sinew_" ;;
    esac
    # D/B/G/S/C/V: writable (or common/weak) data — a global two hosts could fight over.
    case $type in
    D | d | B | b | G | g | S | s | C | V | v)
        violation "exported symbol '$name' is writable data (nm type $type)" ;;
    esac
done <"$tmp/exports.txt"

# --- the public API the headers promise: every SINEW_API function declaration ---
# Comments and preprocessor lines are removed first so that prose mentioning SINEW_API
# and the macro's own definition are not taken for declarations.
cat "$headers"/*.h "$headers"/*/*.h 2>/dev/null | perl -0777 -ne '
    s{/\*.*?\*/}{ }gs;
    s{//[^\n]*}{}g;
    s{^[ \t]*#(?:[^\n]*\\\n)*[^\n]*}{}mg;
    while (/\bSINEW_API\b([^;{}()]*?)\b([A-Za-z_][A-Za-z0-9_]*)\s*\(/g) { print "$2\n"; }
' | sort -u >"$tmp/declared.txt"

if [ ! -s "$tmp/declared.txt" ]; then
    violation "no SINEW_API function declarations found under $headers"
fi
# Declared but not exported: a host that calls it fails to link or load.
for name in $(comm -23 "$tmp/declared.txt" "$tmp/names.txt"); do
    violation "'$name' is declared SINEW_API in a public header but not exported"
done
# Exported but not declared: a private symbol that hosts could start to depend on.
for name in $(sort -u "$tmp/names.txt" | comm -13 "$tmp/declared.txt" -); do
    case $name in
    sinew_*) violation "'$name' is exported but not declared SINEW_API in any public header" ;;
    esac
done

# --- SONAME: libsinew.so.<major>, the major taken from the header's own macro ---
major=$(sed -n 's/^[[:space:]]*#[[:space:]]*define[[:space:]]\{1,\}SINEW_VERSION_MAJOR[[:space:]]\{1,\}\([0-9]\{1,\}\).*/\1/p' \
    "$headers"/sinew/sinew_base.h "$headers"/sinew_base.h 2>/dev/null | head -n 1)
if [ -z "$major" ]; then
    violation "SINEW_VERSION_MAJOR not found in sinew_base.h under $headers"
    major='?'
fi
if ! readelf -d "$lib" >"$tmp/dyn.txt" 2>"$tmp/readelf.err"; then
    echo "check_exports: readelf failed on $lib:" >&2
    cat "$tmp/readelf.err" >&2
    exit 2
fi
soname=$(sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p' "$tmp/dyn.txt")
if [ "$soname" != "libsinew.so.$major" ]; then
    violation "SONAME is '${soname:-<none>}', expected 'libsinew.so.$major'"
fi

# --- licence: CHOLMOD's Supernodal module is GPL; only the bake and tools may link it ---
if grep -qiE '\(NEEDED\).*\[lib(cholmod|suitesparse|metis)' "$tmp/dyn.txt"; then
    violation "libsinew links CHOLMOD/SuiteSparse/METIS (GPL parts): only the bake may"
fi

if [ "$violations" -gt 0 ]; then
    echo "check_exports: $violations ABI violation(s) in $lib" >&2
    exit 1
fi
echo "check_exports: OK: $count exported sinew_ function(s), SONAME $soname, $(wc -l <"$tmp/declared.txt" | tr -d ' ') declared"
exit 0
