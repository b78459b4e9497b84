#!/usr/bin/env python3
"""Writes the seeds of fuzz_view_asset: a glTF binary that the harness's synthetic blob
(tests/blob_synth.h's fixture with its asset description) was, as far as the viewer can
tell, baked from. Four joints named as the fixture's bones ("Hips", "bone 1".."bone 3",
parents -1, 0, 1, 1) whose node poses are the fixture's bind poses (identity rotations,
translations (0.5 b, 1 + b, -0.25 b)); a rigid prop of 3 vertices hanging below "bone 3"
and a skinned mesh of 4 (assimp lists the prop first: the fixture's two source meshes of 3
and 4 vertices); a clip turning "bone 1" and moving "Hips". Run from the source root:

    python3 tests/fuzz/make_view_asset_seed.py tests/fuzz/corpus/view_asset
"""
import json
import os
import struct
import sys


def pad(b, fill):
    return b + fill * (-len(b) % 4)


def main(out_dir):
    binary = b""
    views, accessors = [], []

    def add(data, fmt, count, ctype, kind, extra=None):
        nonlocal binary
        binary = pad(binary, b"\0")
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
        binary += data
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": kind}
        acc.update(extra or {})
        accessors.append(acc)
        return len(accessors) - 1

    floats = lambda v: struct.pack("<%df" % len(v), *v)
    body = [0.0, 1.0, 0.0, 1.0, 2.0, -0.2, 0.4, 3.2, 0.1, 1.4, 4.1, -0.6]
    pos0 = add(floats(body), None, 4, 5126, "VEC3",
               {"min": [min(body[k::3]) for k in range(3)], "max": [max(body[k::3]) for k in range(3)]})
    idx0 = add(struct.pack("<6H", 0, 1, 2, 1, 3, 2), None, 6, 5123, "SCALAR")
    joints0 = add(struct.pack("<16B", 0, 1, 0, 0, 1, 2, 0, 0, 2, 3, 1, 0, 3, 1, 0, 0), None, 4,
                  5121, "VEC4")
    weights0 = add(floats([0.7, 0.3, 0, 0, 0.5, 0.5, 0, 0, 0.6, 0.3, 0.1, 0, 0.9, 0.1, 0, 0]),
                   None, 4, 5126, "VEC4")
    prop = [0.0, 0.0, 0.0, 0.2, 0.0, 0.0, 0.0, 0.2, 0.0]
    pos1 = add(floats(prop), None, 3, 5126, "VEC3",
               {"min": [min(prop[k::3]) for k in range(3)], "max": [max(prop[k::3]) for k in range(3)]})
    idx1 = add(struct.pack("<3H", 0, 1, 2) + b"\0\0", None, 3, 5123, "SCALAR")
    globals_ = [(0.5 * b, 1.0 + b, -0.25 * b) for b in range(4)]
    ibm = []
    for t in globals_:  # column-major inverses of pure translations
        ibm += [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -t[0], -t[1], -t[2], 1]
    inv_bind = add(floats(ibm), None, 4, 5126, "MAT4")
    times = add(floats([0.0, 0.5, 1.0]), None, 3, 5126, "SCALAR", {"min": [0.0], "max": [1.0]})
    turn = add(floats([0, 0, 0, 1, 0, 0, 0.3826834, 0.9238795, 0, 0, 0, 1]), None, 3, 5126, "VEC4")
    move = add(floats([0, 1, 0, 0.1, 1, 0, 0, 1, 0]), None, 3, 5126, "VEC3")

    def local(b, parent):
        g, p = globals_[b], globals_[parent] if parent >= 0 else (0, 0, 0)
        return [g[k] - p[k] for k in range(3)]

    doc = {
        "asset": {"version": "2.0", "generator": "sinew make_view_asset_seed.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 4]}],
        "nodes": [
            {"name": "Hips", "translation": local(0, -1), "children": [1]},
            {"name": "bone 1", "translation": local(1, 0), "children": [2, 3]},
            {"name": "bone 2", "translation": local(2, 1)},
            {"name": "bone 3", "translation": local(3, 1), "children": [5]},
            {"name": "body", "mesh": 0, "skin": 0},
            {"name": "prop", "mesh": 1, "translation": [0.1, 0.1, 0.0]},
        ],
        "meshes": [
            {"name": "body", "primitives": [{"attributes": {"POSITION": pos0, "JOINTS_0": joints0,
                                                            "WEIGHTS_0": weights0}, "indices": idx0}]},
            {"name": "prop", "primitives": [{"attributes": {"POSITION": pos1}, "indices": idx1}]},
        ],
        "skins": [{"joints": [0, 1, 2, 3], "inverseBindMatrices": inv_bind, "skeleton": 0}],
        "animations": [{"name": "wave", "samplers": [
            {"input": times, "output": turn, "interpolation": "LINEAR"},
            {"input": times, "output": move, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                         {"sampler": 1, "target": {"node": 0, "path": "translation"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(pad(binary, b"\0"))}],
    }
    js = pad(json.dumps(doc, separators=(",", ":")).encode(), b" ")
    binary = pad(binary, b"\0")
    write_glb(os.path.join(out_dir, "four_bones.glb"), js, binary)
    # What the fuzzer found in the viewer (each a refusal now): a skin without inverse bind
    # matrices (legal glTF) crashed assimp 5.2.5 inside the viewer; a vertex at infinity
    # was accepted.
    write_glb(os.path.join(out_dir, "no_inverse_bind.glb"),
              js.replace(b'"inverseBindMatrices"', b'"inverseBindMatricex"'), binary)
    prop_x2 = views[accessors[pos1]["bufferView"]]["byteOffset"] + 24
    write_glb(os.path.join(out_dir, "infinite_vertex.glb"), js,
              binary[:prop_x2] + struct.pack("<f", float("inf")) + binary[prop_x2 + 4:])


def write_glb(path, js, binary):
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(binary)))
        f.write(struct.pack("<I4s", len(js), b"JSON") + js)
        f.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)


if __name__ == "__main__":
    main(sys.argv[1])
