#!/usr/bin/env bash
# The main job: install what is missing, build, bake a real glTF character when the shared
# assets are there (the Fox of ../shared/data/gltf-fox, training on its Survey and Walk
# clips, Run held out) or else a generated sample character (the folding finger), write
# the bake report, run the blob headless against the full-space reference and plain
# skinning, print frame times and the benchmark summary, write pictures, and record the
# character played by sinew-view beside its plain skinning (an MP4, under Xvfb).
#   bash tools/run-main.sh [TETS] [FRAMES]
#     TETS    simulation tets, 1000..2000000 (default: 8000 for the Fox, 20000 for the
#             finger)
#     FRAMES  the finger's clip frames, 4..1000000 (default 30; the bake trains on the
#             first 60%); the Fox brings its own clips
# The arguments are checked before anything is installed, built or deleted (exit 2).
# SINEW_DATA_DIR points at another copy of the shared assets.
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
data=${SINEW_DATA_DIR:-../shared/data}
fox=$data/gltf-fox/Fox.glb
if [ -f "$fox" ]; then default_tets=8000; else default_tets=20000; fi
tets=${1:-$default_tets}
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
ship=()
if [ -f "$fox" ]; then
    character=("$fox" --tets "$tets" --train-clips Survey,Walk --heldout-clips Run)
    name=fox
    echo "== bake: the Fox ($fox), ~${tets} tets filling its render surface; trains on Survey and Walk, Run held out"
else
    character=(--scene finger --tets "$tets" --frames "$frames")
    ship=(--ship-split) # the bench measures the clip's held-out frames: the blob must not train on them
    name=finger
    echo "== bake: finger (no shared assets at $data), ~${tets} tets, a ${frames}-frame folding clip"
fi
build/tools/sinew-bake "${character[@]}" "${ship[@]}" --out "$out/$name.blob" --report "$out/report" \
    --cache "$out/cache" \
    --json | tail -n 1 | tee "$out/bake.json"
echo "== benchmark: full-space reference vs subspace runtime vs plain DQS, same mesh and motion"
build/tools/sinew-bench "${character[@]}" --blob "$out/$name.blob" --out "$out/subspace" \
    --json | tail -n 1 | tee "$out/bench.json"
echo "== pictures"
build/tools/sinew-render --frames "$out/subspace" --grid 3 --out "$out/subspace.png" --quiet
if [ "$name" = finger ]; then
    build/tools/sinew-fullsim --scene finger --tets "$tets" --frames "$frames" --out "$out/full" \
        --json | tail -n 1 | tee "$out/fullsim.json"
    build/tools/sinew-render --frames "$out/full" --grid 3 --out "$out/full.png" --quiet
    echo "wrote $out/full.png (full-space reference): a contact sheet of the clip"
fi
echo "== video: sinew-view under Xvfb, plain skinning beside sinew coloured by the correction"
if [ -x build/tools/sinew-view ] && command -v xvfb-run >/dev/null && command -v ffmpeg >/dev/null; then
    if [ "$name" = fox ]; then view=(--asset "$fox" --clip Walk); else view=(--scene finger); fi
    xvfb-run -a -s "-screen 0 1280x720x24" build/tools/sinew-view --blob "$out/$name.blob" \
        "${view[@]}" --frames 240 --record "$out/$name.mp4" --json | tee "$out/view.json"
    echo "wrote $out/$name.mp4: 4 s of the clip, plain skinning left, sinew right"
else
    echo "(no video: sinew-view, xvfb-run or ffmpeg is missing)"
fi
echo "wrote $out/subspace.png (runtime): a contact sheet of the clip"
echo "wrote $out/report/report.html: the bake report (open it in a browser), $out/report/report.json"
