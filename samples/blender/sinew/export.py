"""The simulated frames out of Blender: shape keys, point caches Blender reads back (PC2
and MDD, both read by the Mesh Cache modifier; MDD by the bundled MDD importer too), and
a glTF whose frames are morph targets."""

import struct

import bpy
import numpy as np

KEY_PREFIX = "sinew_"


def write_pc2(path, frames, start, fps):
    """PC2 (little-endian): 'POINTCACHE2\\0', version 1, points, start frame, sampling,
    samples; then every sample's xyz float32."""
    nv = len(frames[0])
    with open(path, "wb") as f:
        f.write(b"POINTCACHE2\0" + struct.pack("<iiffi", 1, nv, float(start), 1.0, len(frames)))
        for co in frames:
            f.write(np.asarray(co, dtype="<f4").tobytes())


def write_mdd(path, frames, start, fps):
    """MDD (big-endian): frames, points, each frame's time in seconds, then every frame's
    xyz float32."""
    nv = len(frames[0])
    with open(path, "wb") as f:
        f.write(struct.pack(">ii", len(frames), nv))
        f.write(np.array([(start + i) / fps for i in range(len(frames))], dtype=">f4").tobytes())
        for co in frames:
            f.write(np.asarray(co, dtype=">f4").tobytes())


def shape_keys(mesh_obj, frames, first):
    """One shape key a frame, keyed to 1 on its frame and 0 on its neighbours; earlier
    sinew keys of the mesh are replaced. The basis is the rest mesh (call this with the
    preview stopped)."""
    if mesh_obj.data.shape_keys is None:
        mesh_obj.shape_key_add(name="Basis", from_mix=False)
    keys = mesh_obj.data.shape_keys
    for kb in [kb for kb in keys.key_blocks if kb.name.startswith(KEY_PREFIX)]:
        mesh_obj.shape_key_remove(kb)
    names = []
    for i, co in enumerate(frames):
        frame = first + i
        kb = mesh_obj.shape_key_add(name=f"{KEY_PREFIX}{frame:04d}", from_mix=False)
        kb.data.foreach_set("co", np.ascontiguousarray(co, dtype=np.float32).ravel())
        for f, v in ((frame - 1, 0.0), (frame, 1.0), (frame + 1, 0.0)):
            kb.value = v
            kb.keyframe_insert("value", frame=f)
        names.append(kb.name)
    return names


def gltf_morph(arm_obj, mesh_obj, path):
    """The mesh with its sinew shape keys as morph targets and their weights animated,
    through Blender's glTF exporter (the skin left out: the frames are the motion)."""
    selected = [o for o in bpy.context.view_layer.objects if o.select_get()]
    for o in selected:
        o.select_set(False)
    mesh_obj.select_set(True)
    try:
        bpy.ops.export_scene.gltf(
            filepath=path,
            export_format="GLB",
            use_selection=True,
            export_morph=True,
            export_skins=False,
            export_animations=True,
            export_materials="NONE",
        )
    finally:
        mesh_obj.select_set(False)
        for o in selected:
            o.select_set(True)
