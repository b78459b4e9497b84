#!/bin/sh
# Installs a build tree into a scratch prefix and builds the sample host
# (samples/host) against that prefix alone, as an engine would, both with the shared and
# with the static library; then runs the hosts, each loading and stepping a small blob
# when a bake tool is given. tests/install.cmake registers it.
#
# usage: check_install.sh MODE BUILD_DIR SOURCE_DIR SCRATCH_DIR CC [SANITIZE [BAKE]]
#   MODE       find_package: a separate CMake project, find_package(sinew CONFIG REQUIRED)
#              pkg_config:   plain CC with `pkg-config --cflags --libs sinew`
#   SANITIZE   the build's SINEW_SANITIZE (may be empty): a sanitized libsinew needs a
#              host built with the same -fsanitize (the runtime must come first), so the
#              host gets it too.
#   BAKE       the build's sinew-bake: bakes a 1000-tet finger (under a second) for
#              the hosts to step (the bake is the build tree's, not part of the package)
set -eu

mode=$1 build=$2 src=$3 scratch=$4 cc=$5 sanitize=${6:-} bake=${7:-}
prefix=$scratch/prefix
fail() {
    echo "check_install($mode): $*" >&2
    exit 1
}
san_flags=
[ -z "$sanitize" ] || san_flags="-fsanitize=$sanitize -fno-omit-frame-pointer"

rm -rf "$scratch"
mkdir -p "$scratch"
cmake --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
    { cat "$scratch/install.log" >&2; fail "cmake --install failed"; }

# --- the layout ------------------------------------------------------------------------
libdir=
for d in "$prefix"/lib "$prefix"/lib64 "$prefix"/lib/*-linux-gnu; do
    [ -f "$d/libsinew.a" ] && libdir=$d && break
done
[ -n "$libdir" ] || fail "no libsinew.a under $prefix/lib*"
soname=$(readelf -d "$libdir/libsinew.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
case $soname in libsinew.so.[0-9]*) ;; *) fail "SONAME of the installed library is '$soname'" ;; esac
[ -L "$libdir/libsinew.so" ] || fail "libsinew.so is not a symlink"
[ -L "$libdir/$soname" ] || fail "$soname is not a symlink"
real=$(readlink -f "$libdir/libsinew.so")
[ "$(readlink -f "$libdir/$soname")" = "$real" ] || fail "the symlinks name different files"
for h in sinew.h sinew_base.h sinew_types.h sinew_world.h sinew_blob_format.h; do
    [ -f "$prefix/include/sinew/$h" ] || fail "include/sinew/$h not installed"
done
for f in "$libdir/pkgconfig/sinew.pc" "$libdir/cmake/sinew/sinewConfig.cmake" \
    "$libdir/cmake/sinew/sinewConfigVersion.cmake" "$libdir/cmake/sinew/sinewTargets.cmake"; do
    [ -f "$f" ] || fail "$f not installed"
done
# Nothing of the bake side: its libraries are no dependency of the package.
if grep -rilE 'lapack|openblas|cholmod|assimp|cjson' "$libdir/pkgconfig" "$libdir/cmake"; then
    fail "the package names a precompute dependency (files above)"
fi
if readelf -d "$libdir/libsinew.so" | grep -iE 'NEEDED.*(lapack|openblas|cholmod|assimp|cjson)'; then
    fail "libsinew.so needs a precompute library"
fi

blob=
if [ -n "$bake" ]; then
    blob=$scratch/finger.blob
    "$bake" --scene finger --tets 1000 --frames 4 --out "$blob" >"$scratch/bake.log" 2>&1 ||
        { cat "$scratch/bake.log" >&2; fail "the bake of the test blob failed"; }
fi

# usage: run_host EXE KIND; KIND shared: must load libsinew from $libdir; static: none
run_host() {
    exe=$1 kind=$2
    needed=$(readelf -d "$exe" | grep 'NEEDED.*libsinew' || true)
    if [ "$kind" = static ]; then
        [ -z "$needed" ] || fail "$exe (static) needs a shared libsinew: $needed"
    else
        loaded=$(ldd "$exe" | sed -n 's/.*libsinew[^ ]* => \([^ ]*\).*/\1/p')
        [ "$(readlink -f "$loaded")" = "$real" ] ||
            fail "$exe loads libsinew from '$loaded', not from the prefix ($real)"
    fi
    # shellcheck disable=SC2086 # $blob is one word or none
    out=$("$exe" $blob) || fail "$exe failed: $out"
    echo "$kind: $out"
}

case $mode in
find_package)
    for kind in shared static; do
        static=OFF
        [ "$kind" = static ] && static=ON
        hb=$scratch/host-$kind
        if ! cmake -S "$src/samples/host" -B "$hb" -DCMAKE_PREFIX_PATH="$prefix" \
            -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="$san_flags" \
            -DCMAKE_EXE_LINKER_FLAGS="$san_flags" -DSINEW_HOST_STATIC=$static \
            >"$scratch/host-$kind.log" 2>&1 ||
            ! cmake --build "$hb" >>"$scratch/host-$kind.log" 2>&1; then
            cat "$scratch/host-$kind.log" >&2
            fail "the $kind host did not configure or build"
        fi
        run_host "$hb/sinew-host" "$kind"
    done
    ;;
pkg_config)
    command -v pkg-config >/dev/null || fail "pkg-config not found (tools/setup-debian.sh)"
    PKG_CONFIG_PATH=$libdir/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}
    export PKG_CONFIG_PATH
    pkg-config --exists --print-errors sinew || fail "pkg-config does not find sinew"
    pc_libdir=$(pkg-config --variable=libdir sinew)
    [ "$(readlink -f "$pc_libdir")" = "$(readlink -f "$libdir")" ] ||
        fail "sinew.pc's libdir is $pc_libdir, not $libdir"
    # shellcheck disable=SC2046,SC2086 # word splitting of the flags is meant
    "$cc" -std=c99 $san_flags -o "$scratch/host-shared" "$src/samples/host/host.c" \
        $(pkg-config --cflags --libs sinew) || fail "the shared host did not build"
    LD_LIBRARY_PATH=$pc_libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    export LD_LIBRARY_PATH
    run_host "$scratch/host-shared" shared
    # The static link: libsinew.a, then what --static adds (Libs.private,
    # Requires.private); --as-needed drops the -lsinew of Libs, which nothing needs then.
    # shellcheck disable=SC2046,SC2086
    "$cc" -std=c99 $san_flags -o "$scratch/host-static" "$src/samples/host/host.c" \
        $(pkg-config --cflags sinew) "$pc_libdir/libsinew.a" -Wl,--as-needed \
        $(pkg-config --static --libs sinew) || fail "the static host did not build"
    run_host "$scratch/host-static" static
    ;;
*) fail "unknown mode (find_package or pkg_config)" ;;
esac
echo "check_install($mode): ok"
