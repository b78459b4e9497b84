#!/bin/sh
# The engine's build: a fresh copy of the source (the files git tracks, as a clone has
# them) configured with -DSINEW_BUILD_BAKE=OFF, which must not look for any of the bake's
# packages (assimp, CHOLMOD, OpenBLAS, LAPACKE, libcjson): the configure runs with
# --debug-find and neither its log nor its cache may name them. It builds (the runtime
# only), installs the runtime component, then the development component, each checked
# for its own files, and the sample host (samples/host) is built against that prefix
# with find_package(sinew) and run, stepping a small blob when a bake tool is given.
# tests/install.cmake registers it.
#
# usage: check_runtime_only.sh SOURCE_DIR SCRATCH_DIR CC CXX WERROR [BAKE]
#   WERROR   the build's SINEW_WERROR (ON/OFF), passed on to the copy's configure
#   BAKE     the build's sinew-bake: bakes a 1000-tet finger for the host to step
set -eu

src=$1 scratch=$2 cc=$3 cxx=$4 werror=$5 bake=${6:-}
copy=$scratch/src build=$scratch/build prefix=$scratch/prefix
fail() {
    echo "check_runtime_only: $*" >&2
    exit 1
}
# The bake's libraries, as their names appear in find calls and in a cache.
bake_libs='assimp|cholmod|suitesparse|lapack|openblas|cjson'

rm -rf "$scratch"
mkdir -p "$copy"

# --- a fresh copy of the source ---------------------------------------------------------
# The files a clone would have (tracked, plus new ones not ignored: a commit in the
# making), not the build trees beside them. Without git (a source archive), all of it
# but the build folders.
if git -C "$src" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    (cd "$src" && git ls-files --cached --others --exclude-standard |
        while IFS= read -r f; do [ -e "$f" ] && printf '%s\n' "$f"; done |
        tar -cf - -T -) | tar -C "$copy" -xf -
else
    (cd "$src" && tar -cf - --exclude='./build*' --exclude=./.git .) | tar -C "$copy" -xf -
fi
[ -f "$copy/CMakeLists.txt" ] || fail "the copy of $src has no CMakeLists.txt"

# --- configure: the bake's packages are never looked for --------------------------------
if ! cmake -S "$copy" -B "$build" --debug-find -DSINEW_BUILD_BAKE=OFF \
    -DCMAKE_BUILD_TYPE=Release -DSINEW_WERROR="$werror" -DSINEW_SANITIZE= \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" >"$scratch/configure.log" 2>&1; then
    cat "$scratch/configure.log" >&2
    fail "the runtime-only configure failed"
fi
# --debug-find prints every find call with the names it looks for; a call for one of the
# bake's libraries would name it.
if grep -inE "$bake_libs" "$scratch/configure.log" >"$scratch/found.txt"; then
    head -n 20 "$scratch/found.txt" >&2
    fail "the runtime-only configure looked for a bake package (configure.log lines above)"
fi
if grep -iE "^[^#/]*($bake_libs)" "$build/CMakeCache.txt"; then
    fail "the runtime-only cache has entries of a bake package (above)"
fi
# The samples, tools and tests link the bake: without it they are not targets at all.
targets=$(cmake --build "$build" --target help 2>&1) || fail "no target list: $targets"
if printf '%s\n' "$targets" | grep -E '(sinew-|sinew_pc_|sinew_samples|test_)'; then
    fail "the runtime-only configure has targets of the bake, tools or tests (above)"
fi

# --- build: the runtime alone -----------------------------------------------------------
if ! cmake --build "$build" -j 2 >"$scratch/build.log" 2>&1; then
    tail -n 40 "$scratch/build.log" >&2
    fail "the runtime-only build failed"
fi

# --- install, component by component ----------------------------------------------------
# usage: listing: every file and link under the prefix, relative, sorted
listing() { (cd "$prefix" && find . ! -type d | sed 's|^\./||' | sort); }
cmake --install "$build" --component runtime --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
    { cat "$scratch/install.log" >&2; fail "cmake --install --component runtime failed"; }
runtime_files=$(listing)
# shellcheck disable=SC2086 # one line of names
echo "runtime component:" $runtime_files
for f in $runtime_files; do
    case $f in
    lib*/libsinew.so.[0-9]*) ;;
    *) fail "the runtime component installs $f (only libsinew.so.<version> belongs in it)" ;;
    esac
done
[ -n "$runtime_files" ] || fail "the runtime component installs nothing"
cmake --install "$build" --component development --prefix "$prefix" >>"$scratch/install.log" 2>&1 ||
    { cat "$scratch/install.log" >&2; fail "cmake --install --component development failed"; }
libdir=$(dirname "$(listing | grep -m 1 'libsinew\.so\.')")
libdir=$prefix/$libdir
for f in "$libdir/libsinew.so" "$libdir/libsinew.a" "$prefix/include/sinew/sinew.h" \
    "$libdir/pkgconfig/sinew.pc" "$libdir/cmake/sinew/sinewConfig.cmake"; do
    [ -e "$f" ] || fail "the development component did not install $f"
done
[ ! -e "$prefix/bin" ] || fail "a runtime-only install has a bin folder: $(ls "$prefix/bin")"
if readelf -d "$libdir/libsinew.so" | grep -iE "NEEDED.*($bake_libs)"; then
    fail "libsinew.so needs a bake library"
fi

# --- the sample host against the prefix -------------------------------------------------
blob=
if [ -n "$bake" ]; then
    blob=$scratch/finger.blob
    "$bake" --scene finger --tets 1000 --frames 4 --out "$blob" >"$scratch/bake.log" 2>&1 ||
        { cat "$scratch/bake.log" >&2; fail "the bake of the test blob failed"; }
fi
hb=$scratch/host
if ! cmake -S "$copy/samples/host" -B "$hb" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_C_COMPILER="$cc" >"$scratch/host.log" 2>&1 ||
    ! cmake --build "$hb" >>"$scratch/host.log" 2>&1; then
    cat "$scratch/host.log" >&2
    fail "the host did not configure or build against the runtime-only prefix"
fi
loaded=$(ldd "$hb/sinew-host" | sed -n 's/.*libsinew[^ ]* => \([^ ]*\).*/\1/p')
[ "$(readlink -f "$loaded")" = "$(readlink -f "$libdir/libsinew.so")" ] ||
    fail "the host loads libsinew from '$loaded', not from the prefix"
# shellcheck disable=SC2086 # $blob is one word or none
out=$("$hb/sinew-host" $blob) || fail "the host failed: $out"
echo "host: $out"
echo "check_runtime_only: ok"
