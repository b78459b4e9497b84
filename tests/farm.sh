#!/usr/bin/env bash
# The bake in work items (docs/baking.md, "Baking on a farm"): shards of a small finger
# solved into a shared cache in any number and order, then the plain bake with that
# cache, give the local bake's blob byte for byte, the adaptive loop's rounds too (N = 1,
# 2, 3 and 7 shards a round, each in a shuffled order); and
# the shared cache's faults each end in the same bytes: a corrupted, truncated or
# foreign entry (detected, redone, never read), a shard killed with SIGKILL mid-solve
# and run again, two shards on the same items at once, a shard that never ran (the
# reduce solves the items it left and names them). Bad --shard values, a manifest of
# another character and a cache that is not a folder are clear errors.
#   bash tests/farm.sh BUILD_DIR [ADAPTIVE_SHARD_COUNTS (default "1 2 3 7")]
set -uo pipefail
bake=$1/tools/sinew-bake
adaptive_counts=${2:-1 2 3 7}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() {
    echo "FAIL $*" >&2
    fails=$((fails + 1))
}
finger=(--scene finger --tets 2000 --threads 2)

# shards I (in the order given) of N into cache $1
run_shards() {
    local cache=$1 n=$2
    shift 2
    for i in "$@"; do
        "$bake" "${finger[@]}" "${extra[@]}" --shard "$i/$n" --cache "$cache" \
            2>>"$tmp/shards.log" || fail "shard $i/$n exited $?"
    done
}
reduce() {
    "$bake" "${finger[@]}" "${extra[@]}" --cache "$1" --out "$2" >/dev/null 2>"$2.log" ||
        fail "reduce into $2 exited $?"
}
same() {
    cmp -s "$1" "$2" || fail "$3: $1 differs from $2"
}

extra=()
"$bake" "${finger[@]}" --out "$tmp/local.blob" >/dev/null 2>&1 || fail "local bake"
"$bake" "${finger[@]}" --plan "$tmp/plan.json" 2>/dev/null || fail "plan"
grep -q '"sinew_plan":1' "$tmp/plan.json" && grep -q '"key":"[0-9a-f]\{16\}"' "$tmp/plan.json" ||
    fail "plan: no items in $(head -c 200 "$tmp/plan.json")"

# N = 1, 2, 3, 7 in shuffled orders
run_shards "$tmp/c1" 1 0
run_shards "$tmp/c2" 2 1 0
run_shards "$tmp/c3" 3 2 0 1
run_shards "$tmp/c7" 7 6 3 0 5 2 4 1
for n in 1 2 3 7; do
    reduce "$tmp/c$n" "$tmp/n$n.blob"
    same "$tmp/n$n.blob" "$tmp/local.blob" "N=$n"
    grep -q "0 of them solved" "$tmp/n$n.blob.log" || fail "N=$n: the reduce solved poses"
done

# a shard checks the manifest: another character's is refused before any solve
"$bake" --scene finger --tets 1000 --shard 0/2 --cache "$tmp/cx" --plan "$tmp/plan.json" \
    2>"$tmp/err" && fail "foreign manifest accepted"
grep -q "another character" "$tmp/err" || fail "foreign manifest: $(cat "$tmp/err")"
# a bad --shard, --shard without --cache, a cache that is not a folder
for bad in 2/2 -1/2 1/0 x/2 1/2/3; do
    "$bake" "${finger[@]}" --shard "$bad" --cache "$tmp/cx" 2>"$tmp/err"
    [ $? -eq 2 ] && grep -q "wants I/N" "$tmp/err" || fail "--shard $bad: $(cat "$tmp/err")"
done
"$bake" "${finger[@]}" --shard 0/2 2>"$tmp/err"
[ $? -eq 2 ] && grep -q "give --cache" "$tmp/err" || fail "--shard without --cache"
touch "$tmp/afile"
"$bake" "${finger[@]}" --shard 0/2 --cache "$tmp/afile" 2>"$tmp/err"
[ $? -eq 1 ] && grep -q "cannot create or write" "$tmp/err" || fail "cache a file: $(cat "$tmp/err")"

# faults on copies of the full cache c2
entries() { ls "$1"/simulate-*.bin; }
cp -r "$tmp/c2" "$tmp/bad"
mapfile -t e < <(entries "$tmp/bad")
half=$(($(stat -c %s "${e[0]}") / 2))
printf '\x55' | dd of="${e[0]}" bs=1 seek="$half" conv=notrunc status=none # corrupted
head -c 1000 "${e[1]}" >"$tmp/cut" && mv "$tmp/cut" "${e[1]}"         # truncated
cp "${e[2]}" "${e[3]}"                                                  # foreign
reduce "$tmp/bad" "$tmp/bad.blob"
same "$tmp/bad.blob" "$tmp/local.blob" "damaged entries"
for why in "checksum mismatch" "made for other inputs"; do
    grep -q "$why" "$tmp/bad.blob.log" || fail "damaged entries: no '$why' in the log"
done
reduce "$tmp/bad" "$tmp/bad2.blob" # the reduce stored the redone entries
grep -q "0 of them solved" "$tmp/bad2.blob.log" || fail "damaged entries not stored again"

# a shard killed with SIGKILL mid-solve, then run again: killed as soon as its first item
# is in the cache, so that the others are still to solve (a fixed delay let a quiet
# machine finish the whole shard first, and the case tested nothing)
"$bake" "${finger[@]}" --threads 1 --shard 0/1 --cache "$tmp/kill" 2>/dev/null &
pid=$!
for _ in $(seq 1200); do # at most 2 minutes
    ls "$tmp/kill" 2>/dev/null | grep -q '^simulate-[0-9a-f]*\.bin$' && break
    sleep 0.1
done
kill -KILL "$pid" 2>/dev/null || fail "the shard to kill had finished: the case tested nothing"
wait "$pid" 2>/dev/null
done_items=$(ls "$tmp/kill" 2>/dev/null | grep -c '^simulate-[0-9a-f]*\.bin$')
all_items=$(grep -o '"key":' "$tmp/plan.json" | wc -l)
[ "$done_items" -lt "$all_items" ] ||
    fail "killed shard: $done_items of $all_items items already done, nothing left mid-solve"
[ -n "$(ls "$tmp/kill" 2>/dev/null | grep -v '^simulate-[0-9a-f]*\.bin$\|\.tmp-')" ] &&
    fail "killed shard left $(ls "$tmp/kill")"
run_shards "$tmp/kill" 1 0
reduce "$tmp/kill" "$tmp/kill.blob"
same "$tmp/kill.blob" "$tmp/local.blob" "killed shard rerun"

# two shards on the same items at once
"$bake" "${finger[@]}" --shard 0/1 --cache "$tmp/twice" 2>/dev/null &
p1=$!
"$bake" "${finger[@]}" --shard 0/1 --cache "$tmp/twice" 2>/dev/null &
p2=$!
wait "$p1" || fail "first of two shards"
wait "$p2" || fail "second of two shards"
reduce "$tmp/twice" "$tmp/twice.blob"
same "$tmp/twice.blob" "$tmp/local.blob" "two shards at once"
grep -q "0 of them solved" "$tmp/twice.blob.log" || fail "two shards: entries unusable"

# a shard that never ran: the reduce solves its items and names them
mkdir -p "$tmp/half"
run_shards "$tmp/half" 2 0
reduce "$tmp/half" "$tmp/half.blob"
same "$tmp/half.blob" "$tmp/local.blob" "missing shard"
grep -q "work items not in the cache, solving them" "$tmp/half.blob.log" ||
    fail "missing shard: the reduce did not say which items it solved"

# the adaptive loop as rounds of items: each round's shards, then the reduce
extra=(--adaptive 2)
"$bake" "${finger[@]}" "${extra[@]}" --out "$tmp/ad.blob" >/dev/null 2>&1 || fail "local adaptive"
for n in $adaptive_counts; do
    case $n in # the shards of each round in a shuffled order
    1) order="0" ;;
    2) order="1 0" ;;
    3) order="2 0 1" ;;
    7) order="6 3 0 5 2 4 1" ;;
    *)
        fail "no shard order for $n shards"
        continue
        ;;
    esac
    : >"$tmp/shards.log"
    for _ in 0 1 2 3; do # one round more than the loop has: its shards find nothing to do
        # shellcheck disable=SC2086 # the order's shards, one word each
        run_shards "$tmp/cad$n" "$n" $order
    done
    grep -q "every round in the cache" "$tmp/shards.log" ||
        fail "adaptive, $n shards: the rounds never ended"
    reduce "$tmp/cad$n" "$tmp/ad$n.blob"
    same "$tmp/ad$n.blob" "$tmp/ad.blob" "adaptive, $n shards"
done

[ "$fails" -eq 0 ] && echo "farm: all cases passed"
exit $((fails > 0))
