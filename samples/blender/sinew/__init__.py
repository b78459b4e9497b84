"""sinew for Blender: bake a rigged mesh with sinew-bake, preview the simulated flesh
while scrubbing, export it as shape keys, point caches or a glTF with morph targets.

libsinew.so is called through ctypes and sinew-bake run as a process; nothing is compiled
for Blender. docs/blender.md says how to install and use it.
"""

bl_info = {
    "name": "sinew",
    "author": "sinew",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Object > sinew (on a mesh deformed by an armature)",
    "description": "Physics-based skinning: bake, preview and export simulated flesh",
    "category": "Animation",
}

import os
import time

import bpy
import numpy

# Debian 12's Blender 3.4 glTF importer still calls numpy.bool, which numpy 1.24 (the
# same Debian's) removed; the alias keeps Blender's own importer working.
if "bool" not in vars(numpy):
    numpy.bool = numpy.bool_

from . import bake, binding, colliders, export, sinew_lib  # noqa: E402

# one preview a mesh object, by name: what the frame handler steps
_previews = {}
_libs = {}


def prefs():
    addon = bpy.context.preferences.addons.get(__name__)
    return addon.preferences if addon else None


def library():
    """The loaded libsinew (preference, else $SINEW_LIB, else the system's), once."""
    p = prefs()
    path = sinew_lib.find_library(bpy.path.abspath(p.library_path) if p and p.library_path else "")
    if path not in _libs:
        _libs[path] = sinew_lib.Library(path)
    return _libs[path]


def armature_of(mesh_obj):
    for m in mesh_obj.modifiers:
        if m.type == "ARMATURE" and m.object:
            return m.object
    if mesh_obj.parent and mesh_obj.parent.type == "ARMATURE":
        return mesh_obj.parent
    return None


def character_meshes(mesh_obj):
    """The mesh and every other mesh its armature deforms: one character, one bake."""
    arm = armature_of(mesh_obj)
    others = [o for o in bpy.context.scene.objects if o.type == "MESH" and o != mesh_obj and armature_of(o) == arm]
    return [mesh_obj] + sorted(others, key=lambda o: o.name)


def blob_path(mesh_obj):
    s = mesh_obj.sinew
    path = s.blob_path or f"//{bpy.path.clean_name(mesh_obj.name)}.blob"
    if path.startswith("//") and not bpy.data.filepath:
        return None  # "beside the .blend" needs a saved .blend
    return bpy.path.abspath(path)


class SinewPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    library_path: bpy.props.StringProperty(
        name="libsinew.so", subtype="FILE_PATH", description="The shared runtime; empty: $SINEW_LIB, else the system's"
    )
    bake_path: bpy.props.StringProperty(
        name="sinew-bake", subtype="FILE_PATH", description="The bake tool; empty: $SINEW_BAKE, else PATH"
    )

    def draw(self, context):
        self.layout.prop(self, "library_path")
        self.layout.prop(self, "bake_path")


class SinewClip(bpy.types.PropertyGroup):
    name: bpy.props.StringProperty()
    use: bpy.props.EnumProperty(
        items=[("NONE", "Unused", ""), ("TRAIN", "Train", "Bake from it"), ("HELDOUT", "Held out", "Measure on it")],
        default="NONE",
    )


class SinewSettings(bpy.types.PropertyGroup):
    tets: bpy.props.IntProperty(name="Tets", default=8000, min=500, max=500000, description="Simulation tets to fill the mesh with")
    clips: bpy.props.CollectionProperty(type=SinewClip)
    dynamic: bpy.props.BoolProperty(name="Dynamic", description="Flesh that lags and jiggles: baked with inertia modes, previewed forward only")
    blob_path: bpy.props.StringProperty(name="Blob", subtype="FILE_PATH", description="Empty: <mesh>.blob beside the .blend")
    report_path: bpy.props.StringProperty(name="Report", subtype="FILE_PATH")
    last_bake: bpy.props.StringProperty(name="Last bake")
    export_dir: bpy.props.StringProperty(name="Export to", subtype="DIR_PATH", default="//")
    soft_group: bpy.props.StringProperty(
        name="Soft region", description="A vertex group where the flesh is softer (its weights blend to Softness)"
    )
    softness: bpy.props.FloatProperty(
        name="Softness",
        default=0.25,
        min=0.001,
        max=1000.0,
        soft_min=0.05,
        soft_max=4.0,
        description="Stiffness multiplier in the soft region: 0.25 is four times softer than the rest, 2 twice as stiff",
    )


def refresh_clips(mesh_obj):
    """The armature's actions as clips, longest first, keeping the choices already made;
    with none made, the two longest train and the next is held out (sinew-bake's own
    default)."""
    arm = armature_of(mesh_obj)
    s = mesh_obj.sinew
    old = {c.name: c.use for c in s.clips}
    names = []
    if arm and arm.animation_data:
        ad = arm.animation_data
        for t in ad.nla_tracks:
            names += [st.action.name for st in t.strips if st.action]
        if ad.action:
            names.append(ad.action.name)
    def length(name):
        first, last = bpy.data.actions[name].frame_range
        return last - first

    s.clips.clear()
    for i, n in enumerate(sorted(set(names), key=length, reverse=True)):
        c = s.clips.add()
        c.name = n
        if old:  # an action new since the last choice is left out until chosen
            c.use = old.get(n, "NONE")
        else:
            c.use = "TRAIN" if i < 2 else "HELDOUT" if i == 2 else "NONE"


def _mesh_and_armature(context):
    obj = context.object
    if obj is None or obj.type != "MESH":
        raise binding.BindError("select the character's mesh")
    arm = armature_of(obj)
    if arm is None:
        raise binding.BindError(f"'{obj.name}' has no armature (an Armature modifier or an armature parent)")
    return obj, arm


class SINEW_OT_refresh_clips(bpy.types.Operator):
    bl_idname = "sinew.refresh_clips"
    bl_label = "Refresh actions"
    bl_description = "List the armature's actions to choose the training and held-out clips from"

    def execute(self, context):
        refresh_clips(context.object)
        return {"FINISHED"}


def start_preview(scene, mesh_obj, record=False):
    """Binds the mesh's blob and steps it at the current frame from now on."""
    stop_preview(mesh_obj)
    path = blob_path(mesh_obj)
    if not path or not os.path.isfile(path):
        raise binding.BindError(f"no blob at {path or '(save the .blend first)'}: bake first")
    blob = sinew_lib.Blob(library(), path)
    world = None
    try:
        b = binding.Binding(blob, armature_of(mesh_obj), mesh_obj, character_meshes(mesh_obj)[1:])
        fps = scene.render.fps / scene.render.fps_base
        if colliders.tagged(scene, [part.obj for part in b.parts] + [b.arm]):
            world = colliders.Colliders(library(), b, scene)
        p = binding.Preview(b, mesh_obj.sinew.dynamic, fps, record, world)
    except Exception:
        if world:
            world.close()
        blob.close()
        raise
    _previews[mesh_obj.name] = p
    _step_previews(scene, None)
    return p


def stop_preview(mesh_obj):
    p = _previews.pop(mesh_obj.name, None)
    if p:
        p.stop()
        p.b.blob.close()
    return p


@bpy.app.handlers.persistent
def _step_previews(scene, depsgraph):
    for name, p in list(_previews.items()):
        arm = p.b.arm
        pose = (arm.evaluated_get(depsgraph) if depsgraph else arm).pose
        try:
            p.update(scene.frame_current, pose.bones)
        except sinew_lib.SinewError as e:
            print(f"sinew: preview of {name} stopped: {e}")
            stop_preview(p.b.mesh)


@bpy.app.handlers.persistent
def _stop_all(*_):
    """Before a save or a load the meshes get their rest positions back."""
    for p in list(_previews.values()):
        stop_preview(p.b.mesh)


class SINEW_OT_preview(bpy.types.Operator):
    bl_idname = "sinew.preview"
    bl_label = "Preview"
    bl_description = "Step the blob from the armature's pose at every frame and show it on the mesh (again: stop)"

    def execute(self, context):
        try:
            obj, _ = _mesh_and_armature(context)
            if stop_preview(obj):
                self.report({"INFO"}, "sinew: preview stopped, rest mesh back")
                return {"FINISHED"}
            start_preview(context.scene, obj)
        except (binding.BindError, sinew_lib.SinewError) as e:
            self.report({"ERROR"}, f"sinew: {e}")
            return {"CANCELLED"}
        self.report({"INFO"}, "sinew: previewing; scrub or play the timeline")
        return {"FINISHED"}


class SINEW_OT_bake(bpy.types.Operator):
    bl_idname = "sinew.bake"
    bl_label = "Bake"
    bl_description = "Export the armature and mesh to glTF and bake them with sinew-bake (Esc cancels)"

    _timer = None
    _proc = None

    def _prepare(self, context):
        """What the bake needs, checked; the mesh's preview stopped (the exporter must see
        the rest mesh)."""
        obj, arm = _mesh_and_armature(context)
        p = prefs()
        exe = bake.find_bake(bpy.path.abspath(p.bake_path) if p and p.bake_path else "")
        path = blob_path(obj)
        if path is None:
            raise bake.BakeError("save the .blend first: the blob is kept beside it")
        if not obj.sinew.clips:
            refresh_clips(obj)
        stop_preview(obj)
        self._obj, self._arm, self._exe, self._path = obj, arm, exe, path
        self._report, self._t0 = os.path.splitext(path)[0] + "_report", time.time()

    def _done(self, summary):
        s = self._obj.sinew
        s.report_path = os.path.join(self._report, "report.html")
        s.last_bake = f"{summary.get('tets', '?')} tets, held-out error {summary.get('err_heldout', '?')}, {time.time() - self._t0:.0f} s"
        self.report({"INFO"}, f"sinew: baked {self._path} ({s.last_bake}); report {s.report_path}")

    def execute(self, context):  # scripts and background Blender: the bake blocks
        try:
            self._prepare(context)
            self._done(bake.run(self._obj.sinew, self._arm, character_meshes(self._obj), self._exe, self._path, self._report))
        except (binding.BindError, bake.BakeError) as e:
            self.report({"ERROR"}, f"sinew: {e}")
            return {"CANCELLED"}
        return {"FINISHED"}

    def invoke(self, context, event):  # the UI: the bake runs while Blender stays usable
        try:
            self._prepare(context)
            self._proc, self._tmp = bake.start(self._obj.sinew, self._arm, character_meshes(self._obj), self._exe, self._path, self._report)
        except (binding.BindError, bake.BakeError) as e:
            self.report({"ERROR"}, f"sinew: {e}")
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._proc.cancel()
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        context.workspace.status_text_set(self._proc.status())
        context.window_manager.progress_update(self._proc.percent)
        if self._proc.poll() is None:
            return {"PASS_THROUGH"}
        context.window_manager.event_timer_remove(self._timer)
        context.window_manager.progress_end()
        context.workspace.status_text_set(None)
        try:
            self._done(self._proc.result())
        except bake.BakeError as e:
            self.report({"ERROR"}, f"sinew: {e}")
            return {"CANCELLED"}
        finally:
            bake.shutil.rmtree(self._tmp, ignore_errors=True)
        return {"FINISHED"}


class SINEW_OT_export(bpy.types.Operator):
    bl_idname = "sinew.export"
    bl_label = "Export"
    bl_description = "Simulate the scene's frame range and write it as shape keys, PC2 and MDD caches and a glTF with morph targets"

    gltf: bpy.props.BoolProperty(name="glTF with morph targets", default=True)

    def execute(self, context):
        try:
            obj, arm = _mesh_and_armature(context)
            out = export_frames(context.scene, obj, bpy.path.abspath(obj.sinew.export_dir), self.gltf)
        except (binding.BindError, sinew_lib.SinewError, OSError) as e:
            self.report({"ERROR"}, f"sinew: {e}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"sinew: exported {', '.join(str(v) for v in out.values())}")
        return {"FINISHED"}


def play(scene, mesh_obj, frames, record=False):
    """Steps a fresh preview over `frames` (scene frames, in order) and returns it stopped,
    its positions in p.frames."""
    stop_preview(mesh_obj)
    scene.frame_set(frames[0])
    p = start_preview(scene, mesh_obj, record)
    for f in frames[1:]:
        scene.frame_set(f)
    stop_preview(mesh_obj)
    return p


def export_frames(scene, mesh_obj, folder, gltf=True):
    """Plays the scene's frame range and writes, for every mesh of the character, shape
    keys, <mesh>.pc2, <mesh>.mdd and, with `gltf`, <mesh>_morph.glb into `folder`. The
    meshes' armature modifiers are left off: the keys hold the whole motion."""
    frames = list(range(scene.frame_start, scene.frame_end + 1))
    p = play(scene, mesh_obj, frames)
    os.makedirs(folder, exist_ok=True)
    fps = scene.render.fps / scene.render.fps_base
    out = {}
    for i, part in enumerate(p.b.parts):
        obj = part.obj
        cos = [p.frames_all[f][i] for f in frames]
        base = os.path.join(folder, bpy.path.clean_name(obj.name))
        files = {"pc2": base + ".pc2", "mdd": base + ".mdd"}
        export.write_pc2(files["pc2"], cos, frames[0], fps)
        export.write_mdd(files["mdd"], cos, frames[0], fps)
        export.shape_keys(obj, cos, frames[0])
        files["shape_keys"] = f"{len(cos)} shape keys"
        for m in obj.modifiers:
            if m.type == "ARMATURE":
                m.show_viewport = m.show_render = False
        if gltf:
            files["gltf"] = base + "_morph.glb"
            export.gltf_morph(armature_of(obj), obj, files["gltf"])
        if i == 0:
            out.update(files)
        else:
            out[obj.name] = files
    return out


class SINEW_PT_collider(bpy.types.Panel):
    bl_label = "sinew collider"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        o = context.object
        return o is not None and o.type in ("MESH", "EMPTY") and not (o.type == "MESH" and armature_of(o))

    def draw(self, context):
        o = context.object
        self.layout.prop(o, "sinew_collider")
        if o.sinew_collider and o.type == "EMPTY":
            kind = "a sphere" if o.empty_display_type == "SPHERE" else "a capsule along local Z"
            self.layout.label(text=f"Collides as {kind} (display size, scale)")


class SINEW_PT_panel(bpy.types.Panel):
    bl_label = "sinew"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH" and armature_of(context.object) is not None

    def draw(self, context):
        obj = context.object
        s, col = obj.sinew, self.layout.column()
        col.prop(s, "tets")
        col.prop(s, "dynamic")
        row = col.row()
        row.label(text="Actions")
        row.operator("sinew.refresh_clips", text="", icon="FILE_REFRESH")
        for c in s.clips:
            row = col.row()
            row.label(text=c.name)
            row.prop(c, "use", expand=True)
        col.prop_search(s, "soft_group", obj, "vertex_groups")
        if s.soft_group:
            col.prop(s, "softness")
        col.prop(s, "blob_path")
        col.operator("sinew.bake", icon="PHYSICS")
        if s.last_bake:
            col.label(text=s.last_bake)
        if s.report_path:
            col.prop(s, "report_path")
        col.operator("sinew.preview", icon="PAUSE" if obj.name in _previews else "PLAY", depress=obj.name in _previews)
        col.prop(s, "export_dir")
        col.operator("sinew.export", icon="EXPORT")


_classes = (
    SinewPreferences,
    SinewClip,
    SinewSettings,
    SINEW_OT_refresh_clips,
    SINEW_OT_preview,
    SINEW_OT_bake,
    SINEW_OT_export,
    SINEW_PT_panel,
    SINEW_PT_collider,
)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Object.sinew = bpy.props.PointerProperty(type=SinewSettings)
    bpy.types.Object.sinew_collider = bpy.props.BoolProperty(
        name="sinew collider", description="The previewed flesh collides with this object (a mesh, or an empty as a sphere or capsule)"
    )
    bpy.app.handlers.frame_change_post.append(_step_previews)
    bpy.app.handlers.save_pre.append(_stop_all)
    bpy.app.handlers.load_pre.append(_stop_all)


def unregister():
    _stop_all()
    for h, fn in (
        (bpy.app.handlers.frame_change_post, _step_previews),
        (bpy.app.handlers.save_pre, _stop_all),
        (bpy.app.handlers.load_pre, _stop_all),
    ):
        if fn in h:
            h.remove(fn)
    del bpy.types.Object.sinew
    del bpy.types.Object.sinew_collider
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
