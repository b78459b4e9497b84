#!/usr/bin/env bash
# The main job: install what is missing, build, bake a generated sample character (the
# folding finger), run it headless against the full-space reference and plain skinning,
# print frame times and the benchmark summary, and write pictures.
#   bash tools/run-main.sh [TETS] [FRAMES]
#     TETS    the finger's resolution, 1000..2000000 (default 20000)
#     FRAMES  clip frames, 4..1000000 (default 30; the bake trains on the first 60%)
# The arguments are checked before anything is installed, built or deleted (exit 2).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() {
    echo "usage: bash tools/run-main.sh [TETS 1000..2000000] [FRAMES 4..1000000]" >&2
    exit 2
}
# check NAME VALUE LO HI: VALUE is a plain decimal integer in LO..HI
check() {
    if ! [[ $2 =~ ^[0-9]{1,7}$ ]] || ((10#$2 < $3 || 10#$2 > $4)); then
        echo "run-main.sh: $1 wants an integer in $3..$4, got '$2'" >&2
        usage
    fi
}
[ $# -le 2 ] || { echo "run-main.sh: at most 2 arguments, got $#" >&2; usage; }
tets=${1:-20000}
frames=${2:-30}
check TETS "$tets" 1000 2000000
check FRAMES "$frames" 4 1000000
tets=$((10#$tets))
frames=$((10#$frames))

bash tools/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"

out=out/main
rm -rf "$out"
mkdir -p "$out"
echo "== bake: finger, ~${tets} tets, a ${frames}-frame folding clip"
build/tools/sinew-bake --scene finger --tets "$tets" --frames "$frames" --out "$out/finger.blob" \
    --json | tail -n 1 | tee "$out/bake.json"
echo "== benchmark: full-space reference vs subspace runtime vs plain DQS, same mesh and motion"
build/tools/sinew-bench --scene finger --tets "$tets" --frames "$frames" --blob "$out/finger.blob" \
    --out "$out/subspace" --json | tail -n 1 | tee "$out/bench.json"
echo "== full-space reference frames (for the picture)"
build/tools/sinew-fullsim --scene finger --tets "$tets" --frames "$frames" --out "$out/full" \
    --json | tail -n 1 | tee "$out/fullsim.json"
echo "== pictures"
build/tools/sinew-render --frames "$out/subspace" --grid 3 --out "$out/subspace.png" --quiet
build/tools/sinew-render --frames "$out/full" --grid 3 --out "$out/full.png" --quiet
echo "wrote $out/subspace.png (runtime) and $out/full.png (full-space reference): contact sheets of the clip"
