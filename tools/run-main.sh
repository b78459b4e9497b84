#!/usr/bin/env bash
# The main job: install what is missing, build, bake a generated sample character (the
# folding finger), run it headless against the full-space reference and plain skinning,
# print frame times and the benchmark summary, and write pictures.
#   bash tools/run-main.sh [TETS] [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
tets=${1:-20000}
frames=${2:-30}

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
