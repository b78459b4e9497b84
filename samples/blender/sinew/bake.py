"""The bake: the armature and its mesh exported with Blender's own glTF exporter, then
sinew-bake run on it as a separate process, its progress lines parsed for the UI."""

import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time

import bpy
import numpy as np

# "sinew-bake: simulate   40% (99/246), 7 s, about 10 s left" (tools/common/tool_run.c)
_PROGRESS = re.compile(r"^sinew-bake: (\w+)\s+(\d+)% \((\d+)/(\d+)\)")
# "sinew-bake: basis          0.40 s  total rank 288, ..." once a stage is done
_STAGE_DONE = re.compile(r"^sinew-bake: (\w+)\s+([0-9.]+) s ")


class BakeError(RuntimeError):
    pass


def find_bake(path=""):
    """sinew-bake: `path` when given, else $SINEW_BAKE, else on PATH."""
    for candidate in (path, os.environ.get("SINEW_BAKE", "")):
        if candidate:
            if not os.access(candidate, os.X_OK):
                raise BakeError(f"sinew-bake not found at {candidate}")
            return os.path.abspath(candidate)  # the bake runs in a temporary folder
    found = shutil.which("sinew-bake")
    if not found:
        raise BakeError("sinew-bake not found: set its path in the add-on's preferences, or SINEW_BAKE")
    return found


def clip_name(arm_obj, action_name):
    """The animation name Blender's glTF exporter gives an action: its NLA track's name
    when it sits in one (the glTF importer stashes every clip in a track), else its own."""
    ad = arm_obj.animation_data
    if ad:
        for track in ad.nla_tracks:
            if any(s.action and s.action.name == action_name for s in track.strips):
                return track.name
    return action_name


# The painted stiffness multiplier as a mesh attribute. Blender 3.4's exporter writes a
# generic attribute as "_" + its name in capitals (export_attributes=True), which is the
# glTF vertex attribute sinew-bake reads: _SINEW_STIFFNESS (precompute/import/gltf_attribute.c).
STIFFNESS_ATTRIBUTE = "sinew_stiffness"


def paint_stiffness(meshes, group, multiplier):
    """Writes the stiffness multiplier 1 + w (multiplier - 1) (w: the vertex's weight in the
    vertex group `group`, 0 outside it) as the FLOAT POINT attribute STIFFNESS_ATTRIBUTE on
    each of `meshes` that has the group and not the attribute already (the artist's own
    painting is left as it is). Returns the mesh data it was added to, for unpaint()."""
    painted = []
    if not group or multiplier == 1.0:
        return painted
    for obj in meshes:
        vg = obj.vertex_groups.get(group)
        me = obj.data
        if vg is None or me in painted or me.attributes.get(STIFFNESS_ATTRIBUTE) is not None:
            continue
        w = np.zeros(len(me.vertices), np.float32)
        for v in me.vertices:
            for g in v.groups:
                if g.group == vg.index:
                    w[v.index] = g.weight
        attr = me.attributes.new(STIFFNESS_ATTRIBUTE, "FLOAT", "POINT")
        attr.data.foreach_set("value", 1.0 + np.clip(w, 0.0, 1.0) * (multiplier - 1.0))
        painted.append(me)
    return painted


def unpaint(painted):
    """Removes what paint_stiffness() added: the scene is as the artist left it."""
    for me in painted:
        attr = me.attributes.get(STIFFNESS_ATTRIBUTE)
        if attr is not None:
            me.attributes.remove(attr)


def export_for_bake(settings, arm_obj, meshes, path):
    """The glTF the bake reads: the meshes painted from the soft region (settings.soft_group,
    settings.softness) for the export only."""
    painted = paint_stiffness(meshes, settings.soft_group, settings.softness)
    try:
        with_paint = any(m.data.attributes.get(STIFFNESS_ATTRIBUTE) is not None for m in meshes)
        export_gltf(arm_obj, meshes, path, attributes=with_paint)
    finally:
        unpaint(painted)
    return painted


def export_gltf(arm_obj, meshes, path, attributes=False):
    """Writes the armature and its meshes, with every action, to `path` (.glb) through
    Blender's exporter (with the meshes' generic attributes when `attributes`); the selection
    is put back afterwards."""
    selected = [o for o in bpy.context.view_layer.objects if o.select_get()]
    active = bpy.context.view_layer.objects.active
    for o in selected:
        o.select_set(False)
    arm_obj.select_set(True)
    for m in meshes:
        m.select_set(True)
    bpy.context.view_layer.objects.active = arm_obj
    try:
        bpy.ops.export_scene.gltf(
            filepath=path,
            export_format="GLB",
            use_selection=True,
            export_animations=True,
            export_nla_strips=True,
            export_skins=True,
            export_morph=False,
            export_apply=False,
            export_materials="NONE",
            export_texcoords=False,
            export_attributes=attributes,
        )
    finally:
        arm_obj.select_set(False)
        for m in meshes:
            m.select_set(False)
        for o in selected:
            o.select_set(True)
        bpy.context.view_layer.objects.active = active


def command(bake_exe, glb, blob, report, tets, train, heldout, dynamic):
    cmd = [bake_exe, glb, "--tets", str(tets), "--out", blob, "--report", report, "--json"]
    if train:
        cmd += ["--train-clips", ",".join(train)]
    if heldout:
        cmd += ["--heldout-clips", ",".join(heldout)]
    if dynamic:
        cmd.append("--inertia-modes")  # basis modes for the flesh's lag and overshoot
    return cmd


class BakeProcess:
    """sinew-bake running in the background; poll() says how far it is."""

    def __init__(self, cmd, workdir):
        self.cmd, self.workdir = cmd, workdir
        self.stage, self.percent, self.lines = "starting", 0, []
        try:
            self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=workdir)
        except OSError as e:
            raise BakeError(f"cannot run {cmd[0]}: {e}") from e
        self.stdout = []
        self._out = threading.Thread(target=lambda: self.stdout.extend(self.proc.stdout), daemon=True)
        self._err = threading.Thread(target=self._read_err, daemon=True)
        self._out.start()
        self._err.start()

    def _read_err(self):
        for line in self.proc.stderr:
            line = line.rstrip("\n")
            self.lines.append(line)
            m = _PROGRESS.match(line)
            if m:
                self.stage, self.percent = m.group(1), int(m.group(2))
                continue
            m = _STAGE_DONE.match(line)
            if m:
                self.stage, self.percent = m.group(1), 100

    def status(self):
        return f"sinew bake: {self.stage} {self.percent}%"

    def poll(self):
        return self.proc.poll()

    def cancel(self):
        self.proc.terminate()

    def result(self):
        """The summary JSON of a finished bake; BakeError with sinew-bake's reason when it
        failed."""
        self._out.join()
        self._err.join()
        rc = self.proc.wait()
        if rc != 0:
            errors = [ln for ln in self.lines if "error" in ln] or self.lines[-3:]
            raise BakeError(f"sinew-bake failed (exit {rc}): " + " | ".join(errors[-3:]))
        text = "".join(self.stdout).strip().splitlines()
        return json.loads(text[-1]) if text else {}


def run(settings, arm_obj, meshes, bake_exe, blob_path, report_dir, on_status=print):
    """The whole bake, blocking (scripts, background Blender): its summary JSON."""
    proc, tmp = start(settings, arm_obj, meshes, bake_exe, blob_path, report_dir)
    shown = ""
    try:
        while proc.poll() is None:
            time.sleep(0.25)
            if proc.status() != shown:
                shown = proc.status()
                on_status(shown)
        return proc.result()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def start(settings, arm_obj, meshes, bake_exe, blob_path, report_dir):
    """Exports the armature and its meshes (the first names the files) and starts sinew-bake; returns the BakeProcess and its temporary
    folder (remove it when the bake is done)."""
    train = [clip_name(arm_obj, c.name) for c in settings.clips if c.use == "TRAIN"]
    heldout = [clip_name(arm_obj, c.name) for c in settings.clips if c.use == "HELDOUT"]
    tmp = tempfile.mkdtemp(prefix="sinew-bake-")
    glb = os.path.join(tmp, bpy.path.clean_name(meshes[0].name) + ".glb")
    export_for_bake(settings, arm_obj, meshes, glb)
    cmd = command(bake_exe, glb, blob_path, report_dir, settings.tets, train, heldout, settings.dynamic)
    return BakeProcess(cmd, tmp), tmp
