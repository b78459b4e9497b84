#!/usr/bin/env bash
# Installs the Debian packages sinew needs to build and test, only those missing.
# Idempotent and silent when everything is present. Runs as root (CI machines have no
# sudo); falls back to sudo only when not root and sudo exists.
set -euo pipefail

packages=(
    build-essential  # gcc, g++, make, binutils (nm, readelf for the ABI tests)
    cmake
    pkg-config
    libembree-dev    # static world colliders (DESIGN.md §4.5)
    libccd-dev       # convex contact (MPR)
    libopenblas-dev  # bake-time dense linear algebra
    liblapacke-dev
    libsuitesparse-dev # CHOLMOD: the reference's sparse direct solve (bake and tools only)
    libassimp-dev    # glTF/FBX import in the bake (DESIGN.md §5)
    libcjson-dev     # world files (precompute/io/world_io.c)
    tetgen           # sinew-bake --mesher tetgen: run as a separate program, never linked (AGPL)
    abigail-tools    # abidw/abidiff: the ABI baseline test (tests/abi/abi_check.sh)
    clang-format     # the format stage of tools/run-tests.sh (Debian 12: clang-format 14)
    python3          # docs/status.md from the benchmarks' JSON (tools/scripts/status_table.py)
    libglfw3-dev     # sinew-view's window and GL context
    libgl-dev        # sinew-view: OpenGL 3.3 core (Mesa)
    libgl1-mesa-dri  # Mesa's llvmpipe: sinew-view without a GPU
    xvfb             # sinew-view's tests and offscreen runs (xvfb-run)
    xauth            # xvfb-run needs it
    ffmpeg           # sinew-view --record
    slurm-wlm        # the farm test: a single-node Slurm cluster (tests/slurm.sh, tools/slurm/)
    munge            # Slurm's authentication daemon
    blender          # the Blender add-on's tests (samples/blender/, Debian 12: Blender 3.4)
    python3-numpy    # Blender's glTF importer needs it (only a recommendation of blender)
)

installed() {
    # dpkg -s also succeeds for removed-but-configured packages; require "installed".
    dpkg -s "$1" 2>/dev/null | grep -q '^Status: .* installed$'
}

missing=()
for p in "${packages[@]}"; do
    installed "$p" || missing+=("$p")
done
[ "${#missing[@]}" -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then
    as_root=()
elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
else
    echo "setup-debian: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
fi

echo "setup-debian: installing ${missing[*]}"
# apt and dpkg chatter goes to a log that is shown only when something fails.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run() {
    if ! ${as_root[@]+"${as_root[@]}"} env DEBIAN_FRONTEND=noninteractive "$@" >"$log" 2>&1; then
        cat "$log" >&2
        echo "setup-debian: failed: $*" >&2
        exit 1
    fi
}
run apt-get update
run apt-get install -y --no-install-recommends "${missing[@]}"

for p in "${missing[@]}"; do
    installed "$p" || { echo "setup-debian: $p still not installed" >&2; exit 1; }
done
echo "setup-debian: done"
