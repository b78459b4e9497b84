#!/usr/bin/env bash
# The main job: install what is missing, build, run the full-space reference on a
# generated sample (the folded finger) with and without self-contact, print its frame
# times and figures, and write pictures of the motion.
#   bash tools/run-main.sh [TETS] [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
tets=${1:-20000}
frames=${2:-12}

bash tools/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"

out=out/main
rm -rf "$out"
mkdir -p "$out"
echo "== full-space reference: finger, ~${tets} tets, ${frames} frames, quasistatic, self-contact on"
build/tools/sinew-fullsim --scene finger --tets "$tets" --frames "$frames" \
    --out "$out/finger" --json | tail -n 1 | tee "$out/finger.json"
echo "== the same without self-contact (penetration for comparison)"
build/tools/sinew-fullsim --scene finger --tets "$tets" --frames "$frames" \
    --no-self-contact --out "$out/finger-nocontact" --json | tail -n 1 | tee "$out/finger-nocontact.json"
echo "== pictures"
build/tools/sinew-render --frames "$out/finger" --grid 3 --out "$out/finger.png"
build/tools/sinew-render --frames "$out/finger-nocontact" --grid 3 --out "$out/finger-nocontact.png"
echo "wrote $out/finger.png and $out/finger-nocontact.png (contact sheets of the motion)"
