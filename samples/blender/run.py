"""Headless sinew in Blender, for pipelines and tests:

    blender -b --factory-startup --python-exit-code 1 -P samples/blender/run.py -- \\
        ASSET --tets N --out DIR [--frames F] [--train A,B] [--heldout C] [--play CLIP]
        [--dynamic] [--lib libsinew.so] [--bake sinew-bake] [--blob F] [--no-gltf] [--no-render]
        [--soft-group NAME | --soft-bone BONE] [--softness X]

imports ASSET (glTF or FBX, Blender's importers), bakes it through the add-on, plays F
frames of a clip through the preview, exports them (PC2, MDD, shape keys, glTF morph
targets), reads the caches and the glTF back, renders one frame with Workbench to
DIR/frame.png, plays the frames again against a sphere collider pressed into the
character's back, and writes DIR/run.json with the figures and DIR/preview_record.json
with the poses the preview stepped (check_replay.py steps them again outside Blender).
A soft region (--soft-group, or --soft-bone: the vertices weighted >= 0.5 on that bone) is
baked --softness times as stiff; the glTF the bake read is kept as DIR/baked.glb and
run.json says how far the region's flesh sits from Blender's skinning.
"""

import argparse
import json
import os
import statistics
import sys
import time

import bpy
import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sinew  # noqa: E402  (the add-on package beside this file)
from sinew import bake, sinew_lib  # noqa: E402


def parse():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="run.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("asset")
    ap.add_argument("--tets", type=int, default=8000)
    ap.add_argument("--out", required=True)
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--train", default="", help="actions (or their glTF clip names) to train on, comma separated")
    ap.add_argument("--heldout", default="", help="actions to hold out, comma separated")
    ap.add_argument("--play", default="", help="the action to preview (default: the first held out)")
    ap.add_argument("--dynamic", action="store_true")
    ap.add_argument("--lib", default="", help="libsinew.so (default $SINEW_LIB)")
    ap.add_argument("--bake", default="", help="sinew-bake (default $SINEW_BAKE, then PATH)")
    ap.add_argument("--blob", default="", help="preview this blob instead of baking (--tets is then ignored)")
    ap.add_argument("--no-gltf", action="store_true")
    ap.add_argument("--no-render", action="store_true")
    ap.add_argument("--soft-group", default="", help="the vertex group of a soft region")
    ap.add_argument("--soft-bone", default="", help="a soft region made of the vertices weighted >= 0.5 on this bone")
    ap.add_argument("--softness", type=float, default=0.25, help="the soft region's stiffness multiplier")
    return ap.parse_args(argv)


def soft_region(mesh_obj, group, bone):
    """The soft region's vertex group: `group`, or one made from the vertices whose weight
    on `bone` is >= 0.5 (weight 1 in it); its name and a mask of its vertices."""
    if bone:
        src = mesh_obj.vertex_groups.get(bone)
        if src is None:
            raise SystemExit(f"run.py: {mesh_obj.name} has no vertex group for bone {bone}")
        group = f"sinew_soft_{bone}"
        vg = mesh_obj.vertex_groups.new(name=group)
        idx = [v.index for v in mesh_obj.data.vertices for g in v.groups if g.group == src.index and g.weight >= 0.5]
        vg.add(idx, 1.0, "REPLACE")
    vg = mesh_obj.vertex_groups.get(group)
    if vg is None:
        raise SystemExit(f"run.py: {mesh_obj.name} has no vertex group {group}")
    mask = np.zeros(len(mesh_obj.data.vertices), bool)
    for v in mesh_obj.data.vertices:
        mask[v.index] = any(g.group == vg.index and g.weight > 0 for g in v.groups)
    return group, mask


def import_asset(path):
    ext = os.path.splitext(path)[1].lower()
    if ext in (".glb", ".gltf"):
        bpy.ops.import_scene.gltf(filepath=path)
    elif ext == ".fbx":
        bpy.ops.import_scene.fbx(filepath=path)
    else:
        raise SystemExit(f"run.py: {path}: not a .glb, .gltf or .fbx file")
    meshes = [o for o in bpy.data.objects if o.type == "MESH" and sinew.armature_of(o)]
    if not meshes:
        raise SystemExit(f"run.py: {path} has no mesh deformed by an armature")
    return max(meshes, key=lambda o: len(o.data.vertices))


def choose_clips(mesh_obj, train, heldout):
    sinew.refresh_clips(mesh_obj)
    arm = sinew.armature_of(mesh_obj)
    wanted = {n: "TRAIN" for n in train} | {n: "HELDOUT" for n in heldout}
    if wanted:
        for c in mesh_obj.sinew.clips:
            c.use = wanted.get(c.name, wanted.get(bake.clip_name(arm, c.name), "NONE"))


def run_bake(mesh_obj, exe):
    path = sinew.blob_path(mesh_obj)
    report = os.path.splitext(path)[0] + "_report"
    t0 = time.time()
    summary = bake.run(mesh_obj.sinew, sinew.armature_of(mesh_obj), sinew.character_meshes(mesh_obj), exe, path, report,
                       lambda s: print(s, flush=True))
    return time.time() - t0, summary, report


def play_action(scene, mesh_obj, name, nframes):
    """Makes `name` the armature's only animation and sets the scene's range to its first
    `nframes` frames."""
    arm = sinew.armature_of(mesh_obj)
    action = bpy.data.actions.get(name) or next(
        (a for a in bpy.data.actions if bake.clip_name(arm, a.name) == name), None
    )
    if action is None:
        raise SystemExit(f"run.py: no action {name}; the file has {', '.join(a.name for a in bpy.data.actions)}")
    ad = arm.animation_data
    for t in ad.nla_tracks:
        t.mute = True
    ad.action = action
    first = int(action.frame_range[0])
    scene.frame_start, scene.frame_end = first, first + nframes - 1
    return action.name


def gltf_back(path, rest, cos, frames, size):
    """The morph-target glTF imported back by Blender's importer: the number of frames'
    shape keys found and their largest distance from the frames written, over the size
    (the file stores deltas from the rest mesh, so float rounding, not 0). The exporter
    splits vertices along seams, so each mesh vertex is found by its rest position."""
    from mathutils.kdtree import KDTree

    before = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=path)
    new = [o for o in bpy.data.objects if o not in before and o.type == "MESH" and o.data.shape_keys]
    worst, found = 0.0, 0
    if new:
        keys = new[0].data.shape_keys.key_blocks
        n = len(new[0].data.vertices)
        basis = np.empty(3 * n, np.float32)
        keys[0].data.foreach_get("co", basis)
        tree = KDTree(n)
        for i, q in enumerate(basis.reshape(-1, 3)):
            tree.insert(q, i)
        tree.balance()
        match = np.array([tree.find(q)[1] for q in rest])
        buf = np.empty(3 * n, np.float32)
        for f, co in zip(frames, cos):
            kb = keys.get(f"{sinew.export.KEY_PREFIX}{f:04d}")
            if kb is None:
                continue
            kb.data.foreach_get("co", buf)
            worst = max(worst, float(np.abs(buf.reshape(-1, 3)[match] - co).max()))
            found += 1
    for o in [o for o in bpy.data.objects if o not in before]:
        bpy.data.objects.remove(o)
    return found, worst / size


def skinned(scene, mesh_obj, frames):
    """The mesh as Blender's Armature modifier deforms it at each frame (mesh space)."""
    out, buf = [], np.empty(3 * len(mesh_obj.data.vertices), np.float32)
    for f in frames:
        scene.frame_set(f)
        mesh_obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices.foreach_get("co", buf)
        out.append(buf.reshape(-1, 3).astype(np.float64))
    return out


def replay_runtime(p, lib_path):
    """The same poses stepped by a second instance straight through the C ABI; the largest
    distance of the mesh's positions (carried back into the blob's space) from it, over
    the character's size."""
    b = p.b
    blob = sinew_lib.Blob(sinew_lib.Library(lib_path), b.blob.path)
    inst = sinew_lib.Instance(blob, p.dynamic)
    out = np.empty(3 * blob.vertex_count, np.float32)
    worst = 0.0
    for rec in p.record:
        if rec["reset"]:
            inst.reset()
        if rec["teleport"]:
            inst.mark_teleport()
        inst.set_pose(np.array(rec["pose"], np.float32))
        inst.step(rec["dt"])
        inst.read_surface(out)
        mine = p.frames[rec["frame"]].astype(np.float64) @ b.A[:3, :3].T + b.A[:3, 3]
        worst = max(worst, float(np.abs(mine - out.reshape(-1, 3)[b.vmap]).max()))
    inst.close()
    blob.close()
    return worst / b.size


def read_back(scene, mesh_obj, path, fmt, frames, cos):
    """The largest difference between the cache read back by Blender's Mesh Cache modifier
    and the frames written (0: exact to float)."""
    m = mesh_obj.modifiers.new("sinew_cache", "MESH_CACHE")
    m.cache_format, m.filepath = fmt, path
    m.frame_start = frames[0]
    bpy.context.view_layer.objects.active = mesh_obj
    bpy.ops.object.modifier_move_to_index(modifier=m.name, index=0)
    shape_mute = mesh_obj.data.shape_keys.key_blocks if mesh_obj.data.shape_keys else []
    for kb in shape_mute:
        kb.mute = True
    worst = 0.0
    buf = np.empty(3 * len(mesh_obj.data.vertices), np.float32)
    for f, co in zip(frames, cos):
        scene.frame_set(f)
        ev = mesh_obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        ev.data.vertices.foreach_get("co", buf)
        worst = max(worst, float(np.abs(buf - co.ravel()).max()))
    for kb in shape_mute:
        kb.mute = False
    mesh_obj.modifiers.remove(m)
    return worst


def collider_pass(scene, mesh_obj, frames, free):
    """A sphere empty tagged as a collider, pressed into the character's back at the middle
    frame; the frames played again with it. Returns the frames with world contact and the
    deepest penetration into the sphere, over its radius, with and without it."""
    mw = np.array(mesh_obj.matrix_world)
    world = lambda co: co.astype(np.float64) @ mw[:3, :3].T + mw[:3, 3]  # noqa: E731
    pts = world(free[frames[len(frames) // 2]])
    lo, hi = pts.min(0), pts.max(0)
    mid, ext = (lo + hi) / 2, hi - lo
    near = (np.abs(pts[:, :2] - mid[:2]) <= 0.15 * ext[:2]).all(1)
    if not near.any():  # a sheet or a ring: nothing above the middle
        near[:] = True
    top = pts[near][np.argmax(pts[near][:, 2])]
    r = 0.1 * float(ext[2])
    centre = top + np.array([0.0, 0.0, 0.6 * r])
    empty = bpy.data.objects.new("sinew_test_sphere", None)
    empty.empty_display_type, empty.empty_display_size = "SPHERE", r
    empty.location = centre.tolist()
    scene.collection.objects.link(empty)
    empty.sinew_collider = True
    p = sinew.play(scene, mesh_obj, frames)
    scene.collection.objects.unlink(empty)

    def depth(cos):
        return max(float((r - np.linalg.norm(world(c) - centre, axis=1)).max()) for c in cos) / r

    contact = sum(1 for n in p.world_contacts if n > 0)
    return contact, p.failed, depth([p.frames[f] for f in frames]), depth([free[f] for f in frames])


def render(scene, mesh_obj, frame, path):
    """One Workbench frame of the character's meshes, seen from the side by an orthographic camera; the
    share of the centre's pixels that are not background."""
    scene.frame_set(frame)
    dg = bpy.context.evaluated_depsgraph_get()
    evs = [o.evaluated_get(dg) for o in sinew.character_meshes(mesh_obj)]
    pts = np.array([ev.matrix_world @ v.co for ev in evs for v in ev.data.vertices])
    lo, hi = pts.min(0), pts.max(0)
    centre, ext = (lo + hi) / 2, hi - lo
    cam_data = bpy.data.cameras.new("sinew_cam")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 1.2 * float(max(ext[0], ext[2], ext[1]))
    cam = bpy.data.objects.new("sinew_cam", cam_data)
    scene.collection.objects.link(cam)
    d = 2.0 * float(np.linalg.norm(ext))
    cam.location = (centre[0] + d, centre[1], centre[2])  # looking along -X at the side
    cam.rotation_euler = (np.pi / 2, 0, np.pi / 2)
    cam_data.clip_end = 4 * d
    scene.camera = cam
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 320, 240, 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    px = np.array(img.pixels[:]).reshape(img.size[1], img.size[0], img.channels)[:, :, :3]
    bg = px[0, 0]
    h, w = px.shape[:2]
    centre_px = px[h // 3 : 2 * h // 3, w // 3 : 2 * w // 3]
    return float((np.abs(centre_px - bg).max(axis=2) > 0.05).mean())


def main():
    a = parse()
    if a.lib:
        os.environ["SINEW_LIB"] = os.path.abspath(a.lib)
    os.makedirs(a.out, exist_ok=True)
    out = os.path.abspath(a.out)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sinew.register()
    mesh_obj = import_asset(os.path.abspath(a.asset))
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "scene.blend"))  # the blob goes beside it
    s = mesh_obj.sinew
    s.tets, s.dynamic = a.tets, a.dynamic
    soft_mask, soft_glb = None, None
    if a.soft_group or a.soft_bone:
        s.soft_group, soft_mask = soft_region(mesh_obj, a.soft_group, a.soft_bone)
        s.softness = a.softness
        soft_glb = os.path.join(out, "baked.glb")  # what the bake reads, to look at
        meshes = sinew.character_meshes(mesh_obj)
        bake.export_for_bake(s, sinew.armature_of(mesh_obj), meshes, soft_glb)
        left = [m.name for m in meshes if m.data.attributes.get(bake.STIFFNESS_ATTRIBUTE) is not None]
    choose_clips(mesh_obj, [n for n in a.train.split(",") if n], [n for n in a.heldout.split(",") if n])
    if a.blob:  # baked before (for this asset through Blender): no bake, the preview's figures
        s.blob_path = os.path.abspath(a.blob)
        bake_s, summary, report = None, {}, ""
    else:
        bake_s, summary, report = run_bake(mesh_obj, bake.find_bake(a.bake))
        print(f"run.py: baked in {bake_s:.1f} s: {summary.get('tets')} tets, held-out error {summary.get('err_heldout')}")

    scene = bpy.context.scene
    held = [c.name for c in s.clips if c.use == "HELDOUT"] or [c.name for c in s.clips]
    played = play_action(scene, mesh_obj, a.play or held[0], a.frames)
    frames = list(range(scene.frame_start, scene.frame_end + 1))
    skin = skinned(scene, mesh_obj, frames)
    p = sinew.play(scene, mesh_obj, frames, record=True)
    # the flesh follows the bones: how far, on average, it sits from Blender's own skinning
    # (a bone mapped wrong puts whole limbs elsewhere)
    scale = float(np.cbrt(np.linalg.det(p.b.A[:3, :3])))  # mesh units -> blob units
    from_skin = max(float(np.linalg.norm(p.frames[f] - k, axis=1).mean()) for f, k in zip(frames, skin))
    from_skin *= scale / p.b.size
    soft_from_skin = None
    if soft_mask is not None and soft_mask.any():  # the soft region's flesh alone, mean over the frames
        soft_from_skin = statistics.mean(
            float(np.linalg.norm(p.frames[f][soft_mask] - k[soft_mask], axis=1).mean()) for f, k in zip(frames, skin)
        )
        soft_from_skin *= scale / p.b.size
    size_m = p.b.size / scale  # the size in the mesh's units
    lib_path = sinew_lib.find_library(os.environ.get("SINEW_LIB", ""))
    dev = replay_runtime(p, lib_path)
    overhead = [t - s_ for t, s_ in zip(p.ms_total, p.ms_step)]

    exported = sinew.export_frames(scene, mesh_obj, out, gltf=not a.no_gltf)
    cos = [p.frames[f] for f in frames]
    keys = mesh_obj.data.shape_keys.key_blocks
    buf = np.empty(3 * len(mesh_obj.data.vertices), np.float32)
    key_diff = 0.0
    for f, co in zip(frames, cos):
        keys[f"{sinew.export.KEY_PREFIX}{f:04d}"].data.foreach_get("co", buf)
        key_diff = max(key_diff, float(np.abs(buf - co.ravel()).max()))
    pc2_diff = read_back(scene, mesh_obj, exported["pc2"], "PC2", frames, cos)
    mdd_diff = read_back(scene, mesh_obj, exported["mdd"], "MDD", frames, cos)
    centre = None
    if not a.no_render:
        centre = render(scene, mesh_obj, frames[len(frames) // 2], os.path.join(out, "frame.png"))

    gltf_keys, gltf_dev = (0, None) if a.no_gltf else gltf_back(exported["gltf"], p.b.rest_m, cos, frames, size_m)
    free = {f: p.frames[f] for f in frames}
    contact_frames, collider_failed, pen, pen_free = collider_pass(scene, mesh_obj, frames, free)

    record = {
        "blob": p.b.blob.path,
        "dynamic": p.dynamic,
        "A": p.b.A.tolist(),
        "vmap": p.b.vmap.tolist(),
        "size": p.b.size,
        "frames": p.record,
        "positions": [p.frames[r["frame"]].ravel().tolist() for r in p.record],
    }
    with open(os.path.join(out, "preview_record.json"), "w") as f:
        json.dump(record, f)
    fig = {
        "asset": os.path.abspath(a.asset),
        "mesh": mesh_obj.name,
        "tets": summary.get("tets"),
        "err_heldout": summary.get("err_heldout"),
        "bake_seconds": round(bake_s, 2) if bake_s is not None else None,
        "bake_tool_seconds": summary.get("bake_seconds"),
        "report": os.path.join(report, "report.html") if report else None,
        "played": played,
        "frames": len(frames),
        "failed_steps": p.failed,
        "step_ms_median": statistics.median(p.ms_step),
        "overhead_ms_median": statistics.median(overhead),
        "overhead_ms_mean": statistics.mean(overhead),
        "overhead_ms_p90": float(np.percentile(overhead, 90)),
        "overhead_ms_max": max(overhead),
        "overhead_ms_first": overhead[0],
        "max_dev_runtime": dev,
        "mean_dist_from_skinning": from_skin,
        "shape_key_max_diff": key_diff,
        "pc2_max_diff": pc2_diff,
        "mdd_max_diff": mdd_diff,
        "gltf_morph_keys": gltf_keys,
        "gltf_morph_max_dev": gltf_dev,
        "collider_contact_frames": contact_frames,
        "collider_failed_steps": collider_failed,
        "collider_penetration": pen,
        "collider_penetration_free": pen_free,
        "render": os.path.join(out, "frame.png") if centre is not None else None,
        "render_centre_share": centre,
        "exported": exported,
        "soft_group": s.soft_group or None,
        "softness": s.softness if s.soft_group else None,
        "soft_vertices": int(soft_mask.sum()) if soft_mask is not None else 0,
        "soft_glb": soft_glb,
        "soft_paint_left_behind": left if soft_mask is not None else [],
        "soft_dist_from_skinning": soft_from_skin,
    }
    with open(os.path.join(out, "run.json"), "w") as f:
        json.dump(fig, f, indent=1)
    print("run.py: " + json.dumps(fig))


try:
    main()
except (sinew_lib.SinewError, bake.BakeError, sinew.binding.BindError) as e:
    print(f"run.py: {e}", file=sys.stderr)
    sys.exit(1)
