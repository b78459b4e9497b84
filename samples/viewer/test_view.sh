#!/usr/bin/env bash
# sinew-view under Xvfb (Mesa's llvmpipe is all CI has): a scripted session renders a few
# frames; the screenshots must show the character in the centre, and plain skinning and
# sinew must differ where the correction is. Exit 77 (skipped) without xvfb-run or a
# display; the Fox part needs the shared data (skipped without it, failed with CI=true).
#   test_view.sh BUILD_DIR DATA_DIR finger|fox
set -euo pipefail
build=$1 data=$2 what=$3
here=$(cd "$(dirname "$0")" && pwd)
view=$build/tools/sinew-view bake=$build/tools/sinew-bake replay=$build/tools/sinew-replay
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The runs that open GL: Mesa's driver, loaded by dlopen and unloaded before exit, leaks
# strings LeakSanitizer cannot attribute (its frames read "<unknown module>", so no
# suppression can name it). In a sanitizer build those runs check addresses, not leaks;
# the runs that never open a window (the refusals before it) still check leaks.
gl=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0")
if [ -n "${DISPLAY:-}" ] && [ -z "${SINEW_VIEW_XVFB:-}" ]; then
    run=("${gl[@]}")
elif command -v xvfb-run >/dev/null 2>&1; then
    run=("${gl[@]}" xvfb-run -a -s "-screen 0 1280x720x24")
else
    echo "SKIP: no display and no xvfb-run (tools/setup-debian.sh installs xvfb)"
    exit 77
fi

# refused RC PATTERN WHAT: the run exited 1 with a message matching PATTERN
refused() {
    if [ "$1" != 1 ] || ! grep -q "$2" "$tmp/err"; then
        cat "$tmp/err"
        echo "FAIL: $3 (exit $1)"
        exit 1
    fi
}

# Bad input is a clear error, never a crash.
set +e
"$view" --blob "$tmp/none.blob" --scene finger --frames 1 2>"$tmp/err"; rc=$?
set -e
refused "$rc" "cannot load the blob" "a missing blob"

if [ "$what" = finger ]; then
    "$bake" --scene finger --tets 2000 --frames 12 --out "$tmp/c.blob" >/dev/null
    args=(--blob "$tmp/c.blob" --scene finger)
    frames=60 # the bend's peak: a period of 2 s
    min_diff=20
else
    fox=$data/gltf-fox/Fox.glb
    if [ ! -f "$fox" ]; then
        if [ "${CI:-}" = true ]; then echo "FAIL: $fox is missing and CI=true"; exit 1; fi
        echo "SKIP: $fox absent (real assets; CI=true makes this a failure)"
        exit 77
    fi
    "$bake" "$fox" --tets 4000 --train-clips Survey,Walk --heldout-clips Run \
        --out "$tmp/c.blob" >/dev/null
    args=(--blob "$tmp/c.blob" --asset "$fox" --clip Walk)
    frames=40
    min_diff=30
    # an asset that does not match the blob: the finger's blob has 3 bones
    "$bake" --scene finger --tets 2000 --frames 12 --out "$tmp/f.blob" >/dev/null
    set +e
    "${run[@]}" "$view" --blob "$tmp/f.blob" --asset "$fox" --frames 1 2>"$tmp/err"; rc=$?
    set -e
    refused "$rc" "is no node of the file" "an asset that is not the blob's (its bones by name)"
    # a file assimp aborts on (one flipped bit of a small binary FBX): refused, not a crash
    set +e
    "${run[@]}" "$view" --blob "$tmp/f.blob" \
        --asset "$here/../../tests/fuzz/corpus/scene_import/fbx_assert.fbx" --frames 1 \
        2>"$tmp/err"
    rc=$?
    set -e
    refused "$rc" "assimp died reading it (signal 6" "a file assimp aborts on"
fi

printf '0.5 s\n0.6 s\n' >"$tmp/script" # slow motion on and off again: the script is read
for v in skin sinew; do
    "${run[@]}" "$view" "${args[@]}" --view $v --no-colour --frames $frames --script "$tmp/script" \
        --screenshot "$tmp/$v.png" --json >"$tmp/$v.json"
    cat "$tmp/$v.json"
    python3 "$here/check_shot.py" present "$tmp/$v.png"
done
python3 "$here/check_shot.py" differ "$tmp/skin.png" "$tmp/sinew.png" $min_diff
grep -q "\"frames\": $frames," "$tmp/sinew.json" || { echo "FAIL: frames"; exit 1; }
if [ "$what" = finger ]; then # a world file: the table rises into the finger
    "${run[@]}" "$view" "${args[@]}" --world "$here/../worlds/finger_table.json" --frames 33 \
        --screenshot "$tmp/world.png" >/dev/null
    python3 "$here/check_shot.py" present "$tmp/world.png"
    # a mesh (OBJ) and a hull collider load, are drawn and touch the finger
    "${run[@]}" "$view" "${args[@]}" --world "$here/../worlds/finger_props.json" --frames 20 \
        --json >"$tmp/props.json"
    grep -q '"world_contacts_max": [1-9]' "$tmp/props.json" || {
        cat "$tmp/props.json"; echo "FAIL: the mesh and hull colliders make no contact"; exit 1; }
    # the HUD shows the library's own figures: its phases line against the stats read again
    python3 - "$tmp/props.json" <<'EOS'
import json, re, sys
j = json.load(open(sys.argv[1]))
hud, st = j["hud_phases"], j["stats"]
got = {k: int(re.search(p, hud).group(1)) for k, p in
       (("newton_iterations", r"NEWTON (\d+)"), ("world_contacts", r"WORLD CONTACTS (\d+)"),
        ("patch_vertices", r"PATCH (\d+)"))}
solve = float(re.search(r"SOLVE ([0-9.]+)", hud).group(1))
bad = [k for k in got if got[k] != st[k]] + (["ms_solve"] if abs(solve - st["ms_solve"]) > 0.006 else [])
if bad or st["world_contacts"] == 0:
    sys.exit("FAIL: the HUD (%s) is not the stats %s: %s" % (hud, st, bad or "no contact"))
print("HUD = stats:", hud)
EOS
    sed 's/"sphere"/"cone"/' "$here/../worlds/fox_poke.json" >"$tmp/cone.json"
    set +e
    "${run[@]}" "$view" "${args[@]}" --world "$tmp/cone.json" --frames 1 2>"$tmp/err"
    rc=$?
    set -e
    refused "$rc" "shape 'cone'" "an unknown collider shape"
    # a later key (the first is the collider's placement, which the world API checks)
    sed 's/"rotation": \[1, 0, 0, 0\]}/&, {"frame": 10, "position": [0, 45, 100], "rotation": [0, 0, 0, 0]}/' \
        "$here/../worlds/fox_poke.json" >"$tmp/zero.json"
    set +e
    "${run[@]}" "$view" "${args[@]}" --world "$tmp/zero.json" --frames 1 2>"$tmp/err"
    rc=$?
    set -e
    refused "$rc" "zero quaternion" "a key whose rotation is the zero quaternion"
    # a debug-draw list with a kind the runtime has not, a recording that cannot be created
    set +e
    "$view" "${args[@]}" --debug-draw contacts,hull --frames 1 2>"$tmp/err"; rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q "got 'hull'" "$tmp/err" || {
        cat "$tmp/err"; echo "FAIL: --debug-draw contacts,hull (exit $rc)"; exit 1; }
    set +e
    "$view" "${args[@]}" --record-calls "$tmp/no/such/dir.rec" --frames 1 2>"$tmp/err"; rc=$?
    set -e
    refused "$rc" "record-calls .*cannot create it" "a recording that cannot be created"
else
    # a cross-fade into the held-out Run while the actor walks a quarter circle (50 units a
    # second turning 90 degrees a second: radius 31.8, so 45 from the start after 1 s)
    walked() { # FRAMES EXPECTED_DISTANCE EXPECTED_HEADING TOLERANCE ARGS...
        local frames=$1 dist=$2 yaw=$3 tol=$4
        shift 4
        "${run[@]}" "$view" "${args[@]}" --view sinew --frames "$frames" "$@" \
            --screenshot "$tmp/walk.png" --json >"$tmp/walk.json"
        cat "$tmp/walk.json"
        python3 "$here/check_shot.py" present "$tmp/walk.png"
        python3 - "$tmp/walk.json" "$dist" "$yaw" "$tol" <<'EOS'
import json, math, sys
x, z, yaw = json.load(open(sys.argv[1]))["actor"]
dist, want, tol = (float(a) for a in sys.argv[2:])
if not (abs(yaw - want) < tol and abs(math.hypot(x, z) - dist) < tol):
    sys.exit("FAIL: the actor should be %g from the start heading %g: at (%g, %g) heading %g"
             % (dist, want, x, z, yaw))
EOS
    }
    walked 60 45 90 0.5 --fade-to Run --fade-at 0.2 --fade-time 0.3 --walk 50 --turn 90
    # root motion of a clip animated in place: the hip's sway moves the actor within a
    # cycle and back, across the loop's end (2 loops of the 0.708 s Walk: 85 steps)
    walked 85 0 0 0.1 --root-motion b_Hip_01
    # the poke: a scripted drag pushes a sphere into the Fox's face
    cat >"$tmp/poke" <<'EOS'
1.0 press 0.30 0.45
1.1 move 0.33 0.45
1.2 move 0.36 0.45
1.3 move 0.39 0.45
1.4 move 0.42 0.45
1.5 move 0.45 0.45
2.5 release
EOS
    # with the contacts' debug draw, recording the instance's calls
    "${run[@]}" "$view" "${args[@]}" --view sinew --world "$here/../worlds/fox_poke.json" \
        --script "$tmp/poke" --frames 100 --screenshot "$tmp/poke.png" --json \
        --debug-draw contacts --record-calls "$tmp/poke.rec" >"$tmp/poke.json"
    cat "$tmp/poke.json"
    python3 "$here/check_shot.py" present "$tmp/poke.png"
    python3 - "$tmp/poke.json" <<'EOS'
import json, sys
j = json.load(open(sys.argv[1]))
press, first, most = j["first_press_s"], j["first_contact_s"], j["world_contacts_max"]
if not (press >= 0 and most > 0 and first >= press):
    sys.exit("FAIL: the poke (pressed at %g s) should make the first world contact (%g s; "
             "most %d in a step)" % (press, first, most))
# one contact line a world contact in force, frame by frame; none before the press
lines, before = j["debug_contact_lines_max"], j["debug_contact_lines_before_press"]
if not (0 < lines <= most and before == 0 and j["debug_contact_mismatch_frames"] == 0):
    sys.exit("FAIL: the debug draw's contact lines (most %d, %d before the press, %d frames "
             "off the step's world contacts) should follow the world contacts (most %d)"
             % (lines, before, j["debug_contact_mismatch_frames"], most))
EOS
    # the viewer's recording replays bitwise
    "$replay" --blob "$tmp/c.blob" --recording "$tmp/poke.rec" --json >"$tmp/replay.json" || {
        cat "$tmp/replay.json"; echo "FAIL: sinew-replay of the viewer's recording"; exit 1; }
    tail -1 "$tmp/replay.json"
    python3 - "$tmp/replay.json" <<'EOS'
import json, sys
j = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
if not (j["steps"] >= 90 and j["differing"] == 0):
    sys.exit("FAIL: the replay: %d steps, %d differ" % (j["steps"], j["differing"]))
EOS
fi
if command -v ffmpeg >/dev/null 2>&1; then
    "${run[@]}" "$view" "${args[@]}" --frames 10 --record "$tmp/v.mp4" >/dev/null
    [ -s "$tmp/v.mp4" ] || { echo "FAIL: --record wrote nothing"; exit 1; }
else
    echo "(no ffmpeg: --record not tried)"
fi
echo "sinew-view $what: ok"
