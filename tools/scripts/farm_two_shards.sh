#!/bin/bash
# The Fox at 20K tets: the simulate stage of one shard (2 threads) against two shards at
# once (1 thread each) on a 2-core machine, in one run, then the reduce. The figures of
# docs/notes/farm.md; per-item seconds in OUT_DIR/*.json.
#   bash tools/scripts/farm_two_shards.sh BUILD_DIR [OUT_DIR]
set -u
B=$(cd "${1:?usage: farm_two_shards.sh BUILD_DIR [OUT_DIR]}" && pwd)/tools/sinew-bake
data=${SINEW_DATA:-$(cd "$(dirname "$0")/../../.." && pwd)/shared/data}
out=${2:-$(mktemp -d)}; mkdir -p "$out"; cd "$out" || exit 1
F=("$data/gltf-fox/Fox.glb" --tets 20000 --train-clips Survey,Walk --heldout-clips Run)
rm -rf one one1 two
t0=$(date +%s.%N)
$B "${F[@]}" --threads 2 --shard 0/1 --cache one --json > one.json 2> one.log
t1=$(date +%s.%N)
$B "${F[@]}" --threads 1 --shard 0/2 --cache two --json > two0.json 2> two0.log &
p0=$!
$B "${F[@]}" --threads 1 --shard 1/2 --cache two --json > two1.json 2> two1.log &
p1=$!
wait $p0 $p1
t2=$(date +%s.%N)
echo "one shard (2 threads): $(echo "$t1 - $t0" | bc) s wall"
echo "two shards (1 thread each, at once): $(echo "$t2 - $t1" | bc) s wall"
t3=$(date +%s.%N)
/usr/bin/time -f "%e s reduce" $B "${F[@]}" --cache two --out fox20k.blob > reduce.log 2>&1
t4=$(date +%s.%N)
echo "reduce: $(echo "$t4 - $t3" | bc) s wall"
echo "finished"
