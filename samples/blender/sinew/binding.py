"""How a blob maps onto a Blender armature and mesh, and the preview that steps it.

Three spaces meet here: the blob's rest space R (the baked file's, after the bake's import),
the mesh object's local space M (where mesh.vertices live) and the armature's space. Bone
orientations differ between Blender and the file (the glTF importer turns bones to point
along +Y), so nothing is mapped through bone frames: a bone's sinew transform is its
skinning matrix (posed times inverse rest, which is orientation-free) carried into R by a
similarity A: M -> R, the glTF exporter's axes or a fit of the bone heads (which every
exporter and importer keeps), whichever puts the mesh's rest shape on the blob's.
"""

import time

import numpy as np

from . import sinew_lib


class BindError(RuntimeError):
    """The blob does not fit this armature or mesh; the message says why."""


def _similarity(src, dst):
    """The scale * rotation + translation taking the points `src` onto `dst` in the least
    squares sense (Umeyama 1991), as a 4x4 matrix."""
    mu_s, mu_d = src.mean(0), dst.mean(0)
    s0, d0 = src - mu_s, dst - mu_d
    var = (s0**2).sum() / len(src)
    if var <= 0:
        raise BindError("the armature's bones all sit at one point")
    u, sig, vt = np.linalg.svd(d0.T @ s0 / len(src))
    d = np.ones(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        d[2] = -1
    rot = u @ np.diag(d) @ vt
    scale = (sig * d).sum() / var
    a = np.eye(4)
    a[:3, :3] = scale * rot
    a[:3, 3] = mu_d - scale * rot @ mu_s
    return a


def _matrix(m):
    return np.array([list(row) for row in m], dtype=np.float64)


class Part:
    """One mesh object of the character: its rest positions (M), its space map A: M -> R
    and, for each of its vertices, the output vertex that moves it."""

    def __init__(self, obj):
        self.obj = obj
        self.nv = len(obj.data.vertices)
        rest = np.empty(3 * self.nv, dtype=np.float32)
        obj.data.vertices.foreach_get("co", rest)
        self.rest_m = rest.reshape(-1, 3)
        self.A = self.A_inv = self.vmap = None

    def to_mesh(self, surface):
        """Output surface (R) -> this mesh's vertex positions (M), float32, its order."""
        s = surface.reshape(-1, 3)[self.vmap].astype(np.float64)
        return (s @ self.A_inv[:3, :3].T + self.A_inv[:3, 3]).astype(np.float32)


class Binding:
    """A blob bound to an armature and the meshes it deforms (the first is the one the
    settings live on): the bone order, the space map, the vertex maps. Raises BindError
    naming what does not fit."""

    def __init__(self, blob, arm_obj, mesh_obj, others=()):
        self.blob, self.arm, self.mesh = blob, arm_obj, mesh_obj
        names = blob.bone_names()
        pose_names = [pb.name for pb in arm_obj.pose.bones]
        index = {n: i for i, n in enumerate(pose_names)}
        missing = [n for n in names if n not in index]
        if missing:
            more = f" and {len(missing) - 5} more" if len(missing) > 5 else ""
            raise BindError(
                f"the blob's bones {', '.join(missing[:5])}{more} are not in the armature "
                f"'{arm_obj.name}': bones renamed since the bake, or a blob of another character"
            )
        self.pose_index = np.array([index[n] for n in names])
        self.npose = len(pose_names)

        self.parts = [Part(mesh_obj)] + [Part(o) for o in others if o != mesh_obj]
        rest_r = self._rest_surface()
        self.size = float(np.linalg.norm(rest_r.max(0) - rest_r.min(0)))
        from mathutils.kdtree import KDTree

        self._tree = KDTree(len(rest_r))
        for i, p in enumerate(rest_r):
            self._tree.insert(p, i)
        self._tree.balance()
        arm_w = _matrix(arm_obj.matrix_world)
        a_w = self._space_map(names, arm_w, rest_r)  # world -> R
        for part in self.parts:
            part.A = a_w @ _matrix(part.obj.matrix_world)
            part.A_inv = np.linalg.inv(part.A)
        first = self.parts[0]
        self.A, self.A_inv, self.vmap, self.rest_m, self.nv = first.A, first.A_inv, first.vmap, first.rest_m, first.nv
        # T_b = L P_b Q_b: R -> the bone's rest frame on the right (Q), its posed frame -> R
        # on the left (L); P_b is the pose bone's armature-space matrix
        self.L = a_w @ arm_w
        rest_inv = np.array([np.linalg.inv(_matrix(arm_obj.data.bones[n].matrix_local)) for n in names])
        self.Q = rest_inv @ np.linalg.inv(self.L)

    def _space_map(self, names, arm_w, rest_r):
        """The similarity world -> R, with every part's vertex map under it set. Two
        candidates, the one under which the meshes' rest shapes land on the blob's kept:
        the glTF exporter's axes (Blender's world turned Y-up: exact for what the add-on
        bakes, and for a glTF Blender imported), and the fit of the armature's bone heads
        onto the blob's bind poses (a blob baked from another format; it leaves a free
        turn when the bones are in a line)."""
        candidates = [np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1.0]])]
        heads = np.array([list(self.arm.data.bones[n].head_local) + [1.0] for n in names])
        binds = np.array([self.blob.bone_bind(i)[9:12] for i in range(len(names))])
        try:
            candidates.append(_similarity((heads @ arm_w.T)[:, :3], binds))
        except BindError:
            pass
        best = None
        for a_w in candidates:
            maps = [
                self._vertex_map(part, a_w @ _matrix(part.obj.matrix_world), rest_r, len(self.parts) == 1)
                for part in self.parts
            ]
            worst = max(w for _, w, _ in maps)
            if best is None or worst < best[1]:
                best = (a_w, worst, maps)
        a_w, worst, maps = best
        if worst > 2e-3 * self.size:  # the rest step's correction plus the export's rounding
            bad = max(maps, key=lambda m: m[1])[2]
            raise BindError(
                f"mesh '{bad}' is not the blob's surface (a vertex {worst:.3g} units "
                f"from it, {worst / self.size:.2%} of the size): bake again, or choose the baked mesh"
            )
        for part, (vmap, _, _) in zip(self.parts, maps):
            part.vmap = vmap
        return a_w

    def _rest_surface(self):
        inst = sinew_lib.Instance(self.blob)
        try:
            pose = np.tile(np.array([1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0], np.float32), self.blob.bone_count)
            inst.set_pose(pose)
            inst.step(1.0 / 24.0)
            out = np.empty(3 * self.blob.vertex_count, np.float32)
            inst.read_surface(out)
        finally:
            inst.close()
        return out.reshape(-1, 3).astype(np.float64)

    def _vertex_map(self, part, a, rest_r, single):
        """For each vertex of `part` under the space map `a` the output vertex that moves
        it, the largest distance between the two at rest, and the part's name: the blob's
        output map when the baked file's vertices are this one mesh's (one source mesh,
        same count), else the nearest output vertex."""
        mine = part.rest_m.astype(np.float64) @ a[:3, :3].T + a[:3, 3]
        sources = self.blob.output_sources()
        if single and self.blob.lib.blob_source_mesh_count(self.blob.handle) == 1 and len(sources) == part.nv:
            direct = np.full(part.nv, -1)
            for out, (m, v) in enumerate(sources):
                if 0 <= v < part.nv:
                    direct[v] = out
            if (direct >= 0).all():
                worst = float(np.linalg.norm(rest_r[direct] - mine, axis=1).max())
                if worst <= 2e-3 * self.size:
                    return direct, worst, part.obj.name
        vmap = np.empty(part.nv, dtype=np.int64)
        worst = 0.0
        for j, p in enumerate(mine):
            _, i, d = self._tree.find(p)
            vmap[j] = i
            worst = max(worst, d)
        return vmap, worst, part.obj.name

    def pose_transforms(self, pose_bones, out):
        """Writes the blob-order bone transforms (bone_count x 12 float32) of the posed
        armature into `out`."""
        flat = np.empty(16 * self.npose, dtype=np.float64)
        pose_bones.foreach_get("matrix", flat)
        # foreach_get gives each matrix column after column
        p = flat.reshape(-1, 4, 4).transpose(0, 2, 1)[self.pose_index]
        t = self.L @ p @ self.Q
        out[:, :9] = t[:, :3, :3].reshape(-1, 9)
        out[:, 9:] = t[:, :3, 3]

    def to_mesh(self, surface):
        """Output surface (R) -> the first mesh's vertex positions (M)."""
        return self.parts[0].to_mesh(surface)


class Preview:
    """An instance stepped from the armature's pose at every frame change, written into
    the mesh. Quasistatic: any frame order (backwards resets first). Dynamic: forward one
    frame at a time; a jump back resets, a jump forward is declared a teleport."""

    def __init__(self, binding, dynamic, fps, record=False, colliders=None):
        self.b, self.dynamic, self.dt = binding, dynamic, 1.0 / fps
        # with colliders, flesh pressed beyond the subspace is solved in full space on a
        # patch (subspace condensation); a quarter of the surface bounds it
        patch = binding.blob.vertex_count // 4 if colliders else 0
        self.inst = sinew_lib.Instance(binding.blob, dynamic, patch)
        self.colliders = colliders
        if colliders:
            self.inst.set_world(colliders.world)
        self.world_contacts = []
        nb = binding.blob.bone_count
        self.pose = np.zeros((nb, 12), dtype=np.float32)
        self.surface = np.zeros(3 * binding.blob.vertex_count, dtype=np.float32)
        self.last_frame = None
        self.record = [] if record else None
        # frames: the first mesh's positions a frame; frames_all: every part's
        self.frames, self.frames_all, self.failed = {}, {}, 0
        self.ms_total, self.ms_step = [], []
        self.modifiers = []
        for part in binding.parts:
            for m in part.obj.modifiers:  # the flesh is the simulation's now, not the skinning's
                if m.type == "ARMATURE":
                    self.modifiers.append((part.obj, m.name, m.show_viewport, m.show_render))
                    m.show_viewport = m.show_render = False

    def update(self, frame, pose_bones):
        t0 = time.perf_counter()
        reset = teleport = False
        if self.last_frame is not None and frame == self.last_frame:
            return
        if self.last_frame is None or frame < self.last_frame:
            reset = self.last_frame is not None
        elif self.dynamic and frame != self.last_frame + 1:
            teleport = True
        if reset:
            self.inst.reset()
        if teleport:
            self.inst.mark_teleport()
        self.b.pose_transforms(pose_bones, self.pose)
        self.inst.set_pose(self.pose)
        if self.colliders:
            self.colliders.update()
        t1 = time.perf_counter()
        status = self.inst.step(self.dt)
        t2 = time.perf_counter()
        self.world_contacts.append(self.inst.stats.world_contacts)
        self.inst.read_surface(self.surface)
        cos = []
        for part in self.b.parts:
            co = part.to_mesh(self.surface)
            part.obj.data.vertices.foreach_set("co", co.ravel())
            part.obj.data.update()
            cos.append(co)
        self.last_frame = frame
        if status & sinew_lib.STEP_FAILED:
            self.failed += 1
        self.frames[frame], self.frames_all[frame] = cos[0], cos
        if self.record is not None:
            self.record.append({"frame": frame, "reset": reset, "teleport": teleport, "dt": self.dt, "pose": self.pose.ravel().tolist()})
        t3 = time.perf_counter()
        self.ms_total.append(1e3 * (t3 - t0))
        self.ms_step.append(1e3 * (t2 - t1))

    def stop(self):
        """Puts the rest meshes and the armature modifiers back."""
        for part in self.b.parts:
            part.obj.data.vertices.foreach_set("co", part.rest_m.ravel())
            part.obj.data.update()
        for obj, name, viewport, render in self.modifiers:
            m = obj.modifiers.get(name)
            if m:
                m.show_viewport, m.show_render = viewport, render
        self.inst.close()
        if self.colliders:
            self.colliders.close()
