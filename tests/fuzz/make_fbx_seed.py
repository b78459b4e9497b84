# The FBX seed of the assimp harnesses (fuzz_scene_import.c, fuzz_view_asset.c):
# two_bones.fbx, a 12-vertex box skinned on two bones ("root", "tip") with a 10-frame clip
# bending the tip, written by Blender's own FBX exporter (binary FBX 7.4). Run:
#   blender -b --factory-startup -P tests/fuzz/make_fbx_seed.py -- tests/fuzz/corpus/scene_import/two_bones.fbx
# fbx_assert.fbx beside it is this file with the bits libFuzzer flipped (seed 1) until
# assimp 5.2.5 aborted in its FBX converter: the regression input of assimp_trial.h.
import sys

import bpy

bpy.ops.wm.read_factory_settings(use_empty=True)
arm = bpy.data.armatures.new("Arm")
rig = bpy.data.objects.new("Rig", arm)
bpy.context.scene.collection.objects.link(rig)
bpy.context.view_layer.objects.active = rig
bpy.ops.object.mode_set(mode="EDIT")
root = arm.edit_bones.new("root")
root.head, root.tail = (0, 0, 0), (0, 0, 1)
tip = arm.edit_bones.new("tip")
tip.head, tip.tail, tip.parent = (0, 0, 1), (0, 0, 2), root
bpy.ops.object.mode_set(mode="OBJECT")

ring = ((-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2))
verts = [(x, y, z) for z in (0, 1, 2) for (x, y) in ring]
faces = [(0, 1, 2, 3), (8, 11, 10, 9)]
for k in range(2):
    for i in range(4):
        a, b = 4 * k + i, 4 * k + (i + 1) % 4
        faces.append((a, b, b + 4, a + 4))
mesh = bpy.data.meshes.new("M")
mesh.from_pydata(verts, [], faces)
mesh.update()
body = bpy.data.objects.new("Body", mesh)
bpy.context.scene.collection.objects.link(body)
body.parent = rig
groups = (body.vertex_groups.new(name="root"), body.vertex_groups.new(name="tip"))
for i, v in enumerate(verts):
    w = min(max(v[2] / 2, 0), 1)
    groups[0].add([i], 1 - w, "REPLACE")
    groups[1].add([i], w, "REPLACE")
body.modifiers.new("Armature", "ARMATURE").object = rig

bpy.context.view_layer.objects.active = rig
bpy.ops.object.mode_set(mode="POSE")
bone = rig.pose.bones["tip"]
bone.rotation_mode = "XYZ"
for frame, angle in ((1, 0.0), (10, 0.8)):
    bone.rotation_euler = (angle, 0, 0)
    bone.keyframe_insert("rotation_euler", frame=frame)
bpy.ops.object.mode_set(mode="OBJECT")
bpy.context.scene.frame_start, bpy.context.scene.frame_end = 1, 10

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.export_scene.fbx(filepath=out, add_leaf_bones=False, bake_anim=True,
                         embed_textures=False, use_mesh_modifiers=False)
