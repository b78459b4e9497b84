"""The add-on installed as an artist installs it: a zip through Blender's add-on installer,
enabled, its library found through its preference; then scrubbing a saved scene forward
and back previews, and scrubbing back starts again from rest. Run by tests/blender.sh:

    HOME=TMP blender -b --factory-startup --python-exit-code 1 -P samples/blender/check_install.py -- \\
        sinew.zip libsinew.so DIR/scene.blend
"""

import sys

import bpy

sys.dont_write_bytecode = True


def main():
    zip_path, lib, scene_blend = sys.argv[sys.argv.index("--") + 1 :]
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    if bpy.ops.preferences.addon_enable(module="sinew") != {"FINISHED"}:
        raise SystemExit("check_install: the add-on does not enable")
    import sinew

    sinew.prefs().library_path = lib
    bpy.ops.wm.open_mainfile(filepath=scene_blend)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH" and sinew.armature_of(o))
    bpy.context.view_layer.objects.active = mesh
    scene = bpy.context.scene
    scene.frame_set(scene.frame_start)
    if bpy.ops.sinew.preview() != {"FINISHED"}:
        raise SystemExit("check_install: no preview")
    p = sinew._previews[mesh.name]
    p.record = []
    for f in (scene.frame_start + 5, scene.frame_start + 6, scene.frame_start + 2):
        scene.frame_set(f)
    resets = [r["reset"] for r in p.record]
    if resets != [False, False, True]:
        raise SystemExit(f"check_install: scrubbing back did not reset ({resets})")
    bpy.ops.sinew.preview()  # stops
    if bpy.ops.preferences.addon_disable(module="sinew") != {"FINISHED"}:
        raise SystemExit("check_install: the add-on does not disable")
    print(f"check_install: installed from {zip_path}, library {lib}, scrubbed forward and back")


main()
