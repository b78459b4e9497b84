"""Steps the poses a Blender preview used (run.py's preview_record.json) straight through
libsinew's C ABI, outside Blender, and compares the mesh positions Blender showed.

    SINEW_LIB=build/runtime/libsinew.so python3 samples/blender/check_replay.py DIR/preview_record.json [--tol 1e-6]

Prints the largest distance over the character's size and exits 1 when it is above the
tolerance. Plain python3: ctypes only, no numpy, no Blender.
"""

import argparse
import ctypes
import json
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "sinew"))
import sinew_lib  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("record")
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args()
    with open(a.record) as f:
        rec = json.load(f)
    lib = sinew_lib.Library()
    blob = sinew_lib.Blob(lib, rec["blob"])
    inst = sinew_lib.Instance(blob, rec["dynamic"])
    A, vmap, size = rec["A"], rec["vmap"], rec["size"]
    pose = (ctypes.c_float * (12 * blob.bone_count))()
    out = (ctypes.c_float * (3 * blob.vertex_count))()
    worst = 0.0
    for frame, shown in zip(rec["frames"], rec["positions"]):
        if frame["reset"]:
            inst.reset()
        if frame["teleport"]:
            inst.mark_teleport()
        pose[:] = frame["pose"]
        inst.set_pose(pose)
        inst.step(frame["dt"])
        inst.read_surface(out)
        for j, i in enumerate(vmap):
            m = shown[3 * j : 3 * j + 3]
            for r in range(3):
                x = A[r][0] * m[0] + A[r][1] * m[1] + A[r][2] * m[2] + A[r][3]
                worst = max(worst, abs(x - out[3 * i + r]))
    inst.close()
    blob.close()
    dev = worst / size
    print(f"check_replay: {len(rec['frames'])} frames, {len(vmap)} vertices: largest distance from the runtime {dev:.3g} of the size (tolerance {a.tol:g})")
    return 0 if dev <= a.tol else 1


if __name__ == "__main__":
    sys.exit(main())
