#!/usr/bin/env bash
# Measures the characters of docs/status.md and writes the page from what was measured:
#   bash tools/scripts/status.sh [NAME ...]      (default: every character below)
# Each character is baked (sinew-bake --json) and benchmarked (sinew-bench --json) from
# the build in build/; the JSON lands in docs/status/NAME/ with the commands and the date,
# and tools/scripts/status_table.py turns docs/status/ into docs/status.md. A character
# whose asset is missing from the shared data is skipped with a message. Heavy: the
# whole set takes tens of minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/../.."
data=${SINEW_DATA_DIR:-../shared/data}
bake=build/tools/sinew-bake
bench=build/tools/sinew-bench
[ -x "$bake" ] && [ -x "$bench" ] || { echo "status.sh: build first (cmake --build build)" >&2; exit 1; }

# NAME|what it is|the asset (empty: generated)|the bake's character arguments
rows=(
    "fox|the Fox, a 24-joint game character, Run held out|$data/gltf-fox/Fox.glb|$data/gltf-fox/Fox.glb --tets 8000 --train-clips Survey,Walk --heldout-clips Run"
    "finger|a generated finger folding into itself||--scene finger --tets 20000 --frames 30"
    "hand|the libigl hand on its own clip|$data/hand-libigl|--scene hand-libigl"
    "elephant|the elephant of the CD dataset on its own clip|$data/elephant-cd|--scene elephant-cd"
)

want=("$@")
measure() {
    local name=$1 what=$2 asset=$3 args=$4 dir=docs/status/$1
    if [ -n "$asset" ] && [ ! -e "$asset" ]; then
        echo "status.sh: $name skipped: $asset is missing" >&2
        return 0
    fi
    read -ra a <<<"$args"
    local tmp
    tmp=$(mktemp -d)
    echo "== $name: $bake ${a[*]}" >&2
    "$bake" "${a[@]}" --out "$tmp/$name.blob" --json | tail -n 1 >"$tmp/bake.json"
    echo "== $name: $bench ${a[*]} --blob B" >&2
    "$bench" "${a[@]}" --blob "$tmp/$name.blob" --full-frames 1 --contract-steps 1000 --json |
        tail -n 1 >"$tmp/bench.json"
    mkdir -p "$dir"
    mv "$tmp/bake.json" "$tmp/bench.json" "$dir/"
    {
        echo "name=$name"
        echo "what=$what"
        echo "date=$(date -u +%Y-%m-%d)"
        echo "cores=$(nproc)"
        echo "load=$(cut -d' ' -f1 /proc/loadavg)"
        echo "bake=sinew-bake ${args//$data/DATA} --out B --json"
        echo "bench=sinew-bench ${args//$data/DATA} --blob B --full-frames 1 --contract-steps 1000 --json"
    } >"$dir/run.txt"
    rm -rf "$tmp"
}
for row in "${rows[@]}"; do
    IFS='|' read -r name what asset args <<<"$row"
    if [ "${#want[@]}" -gt 0 ] && [[ ! " ${want[*]} " == *" $name "* ]]; then continue; fi
    measure "$name" "$what" "$asset" "$args"
done
python3 tools/scripts/status_table.py docs/status >docs/status.md
echo "wrote docs/status.md" >&2
