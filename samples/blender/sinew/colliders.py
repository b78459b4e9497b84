"""World colliders from the scene's objects tagged "sinew collider": a mesh collides as its
triangles (solid behind their front faces), an empty drawn as a sphere as a sphere of its
display size, any other empty as a capsule along its local Z (radius its display size
times its X scale, half height its display size times its Z scale). They are placed in
the blob's space through the same map as the bones and moved every previewed frame;
their scale is taken when the preview starts."""

import math

import numpy as np
from mathutils import Matrix

from . import sinew_lib

# sinew's capsule stands along its local y, a Blender empty's axis is its local Z
_Y_TO_Z = np.array(Matrix.Rotation(math.pi / 2, 4, "X"))


def tagged(scene, skip):
    return [o for o in scene.objects if getattr(o, "sinew_collider", False) and o not in skip and o.type in ("MESH", "EMPTY")]


def _split(w):
    """A 4x4 matrix (no shear) as its translation, rotation quaternion and axis scales."""
    scale = np.linalg.norm(w[:3, :3], axis=0)
    rot = Matrix((w[:3, :3] / scale).tolist()).to_quaternion()
    t = sinew_lib.Transform()
    t.position[:] = [float(x) for x in w[:3, 3]]
    t.rotation[:] = [rot.w, rot.x, rot.y, rot.z]
    return t, scale


class Colliders:
    """The tagged objects as a sinew world, in the binding's blob space."""

    def __init__(self, lib, binding, scene):
        self.b, self.items = binding, []
        self.world = sinew_lib.World(lib)
        try:
            for obj in tagged(scene, [part.obj for part in binding.parts] + [binding.arm]):
                self._add(obj)
        except Exception:
            self.world.close()
            raise

    def _matrix(self, obj):
        """The object's frame (a capsule's turned onto its axis) in the blob's space."""
        to_mesh = np.array(self.b.mesh.matrix_world.inverted() @ obj.matrix_world)
        w = self.b.A @ to_mesh
        return w @ _Y_TO_Z if obj.type == "EMPTY" and obj.empty_display_type != "SPHERE" else w

    def _add(self, obj):
        t, scale = _split(self._matrix(obj))
        if obj.type == "MESH":
            mesh = obj.data
            mesh.calc_loop_triangles()
            co = np.empty(3 * len(mesh.vertices), np.float32)
            mesh.vertices.foreach_get("co", co)
            tri = np.empty(3 * len(mesh.loop_triangles), np.int32)
            mesh.loop_triangles.foreach_get("vertices", tri)
            if len(tri) == 0:
                raise sinew_lib.SinewError(f"collider '{obj.name}' has no faces")
            co = (co.reshape(-1, 3) * scale).ravel()
            cid = self.world.add(sinew_lib.SHAPE_MESH, t, vertices=co.tolist(), indices=tri.tolist())
        elif obj.empty_display_type == "SPHERE":
            cid = self.world.add(sinew_lib.SHAPE_SPHERE, t, radius=float(obj.empty_display_size * scale.max()))
        else:  # scale is in the capsule's frame: x, y (its axis), z
            r = float(obj.empty_display_size * scale[0])
            cid = self.world.add(sinew_lib.SHAPE_CAPSULE, t, radius=r, half_height=float(obj.empty_display_size * scale[1]))
        self.items.append((obj, cid))

    def update(self):
        for obj, cid in self.items:
            self.world.move(cid, _split(self._matrix(obj))[0])

    def close(self):
        self.world.close()
