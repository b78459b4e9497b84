#!/bin/sh
# The pipeline's install: `cmake --install BUILD --component tools` into a scratch prefix
# installs the command-line tools and nothing else, and they run from there, in another
# folder, with no LD_LIBRARY_PATH: `--help` of sinew-bake and sinew-bench exits 0, and the
# installed sinew-bake bakes a small finger. tests/install.cmake registers it.
#
# usage: check_install_tools.sh BUILD_DIR SCRATCH_DIR TOOL...
#   TOOL   every tool the build made (each must be installed)
set -eu

build=$1 scratch=$2
shift 2
prefix=$scratch/prefix
fail() {
    echo "check_install_tools: $*" >&2
    exit 1
}

rm -rf "$scratch"
mkdir -p "$scratch/run"
cmake --install "$build" --component tools --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
    { cat "$scratch/install.log" >&2; fail "cmake --install --component tools failed"; }

files=$(cd "$prefix" && find . ! -type d | sed 's|^\./||' | sort)
# shellcheck disable=SC2086 # one line of names
echo "tools component:" $files
for f in $files; do
    case $f in
    bin/sinew-*) ;;
    *) fail "the tools component installs $f (only bin/sinew-* belongs in it)" ;;
    esac
done
for t in "$@"; do
    exe=$prefix/bin/$t
    [ -x "$exe" ] || fail "$t is not installed in $prefix/bin"
    # Every library it needs is found from the prefix alone; its RPATH names no folder of
    # the build tree.
    missing=$(env -u LD_LIBRARY_PATH ldd "$exe" | grep 'not found' || true)
    [ -z "$missing" ] || fail "$t from the prefix: $missing"
    if readelf -d "$exe" | grep -E '(RPATH|RUNPATH)' | grep -F "$build"; then
        fail "$t keeps the build tree in its RPATH"
    fi
done

cd "$scratch/run"
for t in sinew-bake sinew-bench; do
    out=$(env -u LD_LIBRARY_PATH "$prefix/bin/$t" --help 2>&1) ||
        fail "$prefix/bin/$t --help exited $?: $out"
    printf '%s\n' "$out" | grep -qi 'usage' || fail "$t --help printed no usage: $out"
done
env -u LD_LIBRARY_PATH "$prefix/bin/sinew-bake" --scene finger --tets 1000 --frames 4 \
    --out finger.blob >bake.log 2>&1 || { cat bake.log >&2; fail "the installed sinew-bake failed"; }
[ -s finger.blob ] || fail "the installed sinew-bake wrote no blob"
echo "check_install_tools: ok"
