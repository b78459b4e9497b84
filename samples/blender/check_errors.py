"""Bad input through the add-on's operators gives an error report naming the cause, never
a crash: run by tests/blender.sh inside Blender on the scene run.py saved.

    blender -b --factory-startup --python-exit-code 1 -P samples/blender/check_errors.py -- \\
        DIR/scene.blend OTHER.blob

DIR/scene.blend holds the baked mesh (its blob beside it); OTHER.blob is another
character's. Exits 1 when a case is not refused with its message.
"""

import os
import shutil
import sys
import time

import bpy

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sinew  # noqa: E402
from sinew import bake  # noqa: E402


def expect_error(what, words, op):
    try:
        r = op()
    except (RuntimeError, bake.BakeError) as e:  # Blender raises an operator's ERROR report
        msg = str(e)
        missing = [w for w in words if w not in msg]
        if missing:
            raise SystemExit(f"check_errors: {what}: message lacks {missing}: {msg}")
        print(f"check_errors: {what}: refused: {msg.strip()}")
        return
    raise SystemExit(f"check_errors: {what}: not refused ({r})")


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :]
    scene_blend, other = argv[0], argv[1]
    sinew.register()
    bpy.ops.wm.open_mainfile(filepath=scene_blend)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH" and sinew.armature_of(o))
    bpy.context.view_layer.objects.active = mesh
    arm = sinew.armature_of(mesh)
    lib = os.environ["SINEW_LIB"]
    preview = bpy.ops.sinew.preview

    os.environ["SINEW_LIB"] = "/nonexistent/libsinew.so"
    expect_error("a missing library", ["libsinew not found", "/nonexistent"], preview)
    os.environ["SINEW_LIB"] = lib

    mesh.sinew.blob_path = other
    expect_error("another character's blob", ["not in the armature", "bone 0"], preview)

    broken = os.path.join(os.path.dirname(scene_blend), "truncated.blob")
    with open(sinew.blob_path(_default(mesh)), "rb") as f:
        data = f.read()
    with open(broken, "wb") as f:
        f.write(data[: len(data) // 2])
    mesh.sinew.blob_path = broken
    expect_error("a truncated blob", ["cannot load the blob"], preview)

    mesh.sinew.blob_path = ""
    bone = arm.data.bones["b_Tail03_014"] if "b_Tail03_014" in arm.data.bones else arm.data.bones[-1]
    name = bone.name
    bone.name = "renamed_bone"
    expect_error("a missing bone", [name, "not in the armature"], preview)
    bone.name = name

    os.environ["SINEW_BAKE"] = "/nonexistent/sinew-bake"
    expect_error("a missing sinew-bake", ["sinew-bake not found"], bpy.ops.sinew.bake)

    x = mesh.data.vertices[0].co.x
    mesh.data.vertices[0].co.x += 0.25 * sum(mesh.dimensions)  # a mesh edited since the bake
    expect_error("a mesh edited since the bake", ["is not the blob's surface"], preview)
    mesh.data.vertices[0].co.x = x

    check_progress(os.path.dirname(scene_blend))

    if preview() != {"FINISHED"} or mesh.name not in sinew._previews:
        raise SystemExit("check_errors: the good blob does not preview")
    preview()  # stops it
    shutil.os.remove(broken)
    print("check_errors: every case refused with its reason")


def check_progress(workdir):
    """What the status bar shows comes from sinew-bake's progress lines (a stand-in process
    prints them here); a failed bake's error line reaches the report."""
    lines = [
        "sinew-bake: simulate   40% (99/246), 7 s, about 10 s left",
        "sinew-bake: basis          0.40 s  total rank 288",
    ]
    script = "; ".join(f"echo '{ln}' >&2; sleep 0.3" for ln in lines) + "; echo '{\"tets\": 7}'"
    proc = bake.BakeProcess(["sh", "-c", script], workdir)
    shown = set()
    while proc.poll() is None:
        shown.add(proc.status())
        time.sleep(0.05)
    if proc.result() != {"tets": 7} or not {"sinew bake: simulate 40%", "sinew bake: basis 100%"} <= shown:
        raise SystemExit(f"check_errors: the bake's progress read as {sorted(shown)}")
    proc = bake.BakeProcess(["sh", "-c", "echo 'sinew-bake: error: no clip named Jump' >&2; exit 1"], workdir)
    expect_error("a failed bake", ["exit 1", "no clip named Jump"], proc.result)
    print("check_errors: the bake's progress and failure read")


def _default(mesh):
    mesh.sinew.blob_path = ""
    return mesh


main()
