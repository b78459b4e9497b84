# The FBX seeds of the assimp harnesses, written by Blender's own FBX exporter (binary FBX
# 7.4). Run from the source root:
#   blender -b --factory-startup -P tests/fuzz/make_fbx_seed.py -- two_bones tests/fuzz/corpus/scene_import/two_bones.fbx
#   blender -b --factory-startup -P tests/fuzz/make_fbx_seed.py -- four_bones tests/fuzz/corpus/view_asset/four_bones.fbx
# two_bones: a 12-vertex box skinned on two bones ("root", "tip") with a 10-frame clip
# bending the tip (fuzz_scene_import's seed, and fuzz_view_asset's refusal of a file that
# is not the blob's). four_bones: make_view_asset_seed.py's character as FBX, so that
# fuzz_view_asset's synthetic blob maps onto it (bones "Hips", "bone 1".."bone 3" at the
# fixture's bind translations, a rigid 3-vertex prop under "bone 3", a 4-vertex skin).
# fbx_assert.fbx beside two_bones.fbx is that file with the bits libFuzzer flipped (seed 1)
# until assimp 5.2.5 aborted in its FBX converter: the regression input of assimp_trial.h.
import sys

import bpy


def armature(names, heads, parents, tail_of):
    arm = bpy.data.armatures.new("Arm")
    rig = bpy.data.objects.new("Rig", arm)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    bones = []
    for name, head, parent in zip(names, heads, parents):
        b = arm.edit_bones.new(name)
        b.head, b.tail = head, tail_of(head)
        if parent >= 0:
            b.parent = bones[parent]
        bones.append(b)
    bpy.ops.object.mode_set(mode="OBJECT")
    return rig


def skinned_mesh(rig, name, verts, faces, weights, smooth):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    for p in mesh.polygons:
        p.use_smooth = smooth
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.parent = rig
    groups = {}
    for v, row in enumerate(weights):
        for bone, w in row:
            if bone not in groups:
                groups[bone] = obj.vertex_groups.new(name=bone)
            groups[bone].add([v], w, "REPLACE")
    obj.modifiers.new("Armature", "ARMATURE").object = rig
    return obj


def animate(rig, bone, axis, keys):
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="POSE")
    pb = rig.pose.bones[bone]
    pb.rotation_mode = "XYZ"
    for frame, angle in keys:
        e = [0.0, 0.0, 0.0]
        e[axis] = angle
        pb.rotation_euler = e
        pb.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.scene.frame_start, bpy.context.scene.frame_end = 1, keys[-1][0]


def two_bones():
    rig = armature(["root", "tip"], [(0, 0, 0), (0, 0, 1)], [-1, 0],
                   lambda h: (h[0], h[1], h[2] + 1))
    ring = ((-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2))
    verts = [(x, y, z) for z in (0, 1, 2) for (x, y) in ring]
    faces = [(0, 1, 2, 3), (8, 11, 10, 9)]
    for k in range(2):
        for i in range(4):
            a, b = 4 * k + i, 4 * k + (i + 1) % 4
            faces.append((a, b, b + 4, a + 4))
    weights = [[("root", 1 - min(max(v[2] / 2, 0), 1)), ("tip", min(max(v[2] / 2, 0), 1))]
               for v in verts]
    skinned_mesh(rig, "M", verts, faces, weights, smooth=False)
    animate(rig, "tip", 0, [(1, 0.0), (10, 0.8)])


def four_bones():
    names = ["Hips", "bone 1", "bone 2", "bone 3"]
    heads = [(0.5 * b, 1.0 + b, -0.25 * b) for b in range(4)]
    rig = armature(names, heads, [-1, 0, 1, 1], lambda h: (h[0], h[1] + 0.3, h[2]))
    prop = bpy.data.meshes.new("prop")
    prop.from_pydata([(0, 0, 0), (0.2, 0, 0), (0, 0.2, 0)], [], [(0, 1, 2)])
    prop.update()
    obj = bpy.data.objects.new("prop", prop)
    bpy.context.scene.collection.objects.link(obj)
    obj.parent, obj.parent_type, obj.parent_bone = rig, "BONE", "bone 3"
    verts = [(0, 1, 0), (1, 2, -0.2), (0.4, 3.2, 0.1), (1.4, 4.1, -0.6)]
    weights = [[("Hips", 0.7), ("bone 1", 0.3)], [("bone 1", 0.5), ("bone 2", 0.5)],
               [("bone 2", 0.6), ("bone 3", 0.4)], [("bone 3", 0.9), ("bone 1", 0.1)]]
    skinned_mesh(rig, "body", verts, [(0, 1, 2), (1, 3, 2)], weights, smooth=True)
    animate(rig, "bone 1", 2, [(1, 0.0), (15, 0.78)])


bpy.ops.wm.read_factory_settings(use_empty=True)
args = sys.argv[sys.argv.index("--") + 1:]
{"two_bones": two_bones, "four_bones": four_bones}[args[0]]()
bpy.ops.export_scene.fbx(filepath=args[1], add_leaf_bones=False, bake_anim=True,
                         embed_textures=False, use_mesh_modifiers=False)
