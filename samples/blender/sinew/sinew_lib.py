"""libsinew through ctypes: the few calls the add-on makes, with no Blender in sight.

Kept free of bpy and numpy so plain python3 can load it too (the tests replay the poses
Blender used through it). The structs declare only the leading fields the add-on sets:
the library reads only what a def's struct_size covers and takes the rest as defaults.
"""

import ctypes
import ctypes.util
import os

SINEW_OK = 0
STEP_QUASISTATIC = 0
STEP_DYNAMIC = 1
STEP_FAILED = 8

_LOG_FN = ctypes.CFUNCTYPE(None, ctypes.c_int, ctypes.c_uint32, ctypes.c_char_p, ctypes.c_void_p)


class SinewError(RuntimeError):
    """A libsinew call that failed, with the library's reason when it logged one."""


class _Allocator(ctypes.Structure):
    _fields_ = [("alloc", ctypes.c_void_p), ("free", ctypes.c_void_p), ("user", ctypes.c_void_p)]


class _Logger(ctypes.Structure):
    _fields_ = [("log", _LOG_FN), ("user", ctypes.c_void_p), ("max_level", ctypes.c_int)]


class _BlobDef(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("path", ctypes.c_char_p),
        ("data", ctypes.c_void_p),
        ("data_size", ctypes.c_size_t),
        ("allocator", _Allocator),
        ("logger", _Logger),
    ]


class _Tasks(ctypes.Structure):
    _fields_ = [
        ("enqueue", ctypes.c_void_p),
        ("finish", ctypes.c_void_p),
        ("worker_count", ctypes.c_uint32),
        ("user", ctypes.c_void_p),
    ]


class _InstanceDef(ctypes.Structure):
    # the leading fields of sinew_instance_def (sinew_types.h); the rest stay default
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("mode", ctypes.c_int),
        ("max_newton_iters", ctypes.c_uint32),
        ("allocator", _Allocator),
        ("logger", _Logger),
        ("max_contact_pairs", ctypes.c_uint32),
        ("tasks", _Tasks),
        ("max_world_contacts", ctypes.c_uint32),
        ("max_patch_vertices", ctypes.c_uint32),
    ]


class _StepStats(ctypes.Structure):
    # the leading fields of sinew_step_stats
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("newton_iterations", ctypes.c_uint32),
        ("status", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("residual", ctypes.c_double),
        ("energy", ctypes.c_double),
        ("ms_skin", ctypes.c_double),
        ("ms_contact", ctypes.c_double),
        ("ms_dynamics", ctypes.c_double),
        ("ms_solve", ctypes.c_double),
        ("ms_output", ctypes.c_double),
        ("active_vertices", ctypes.c_uint32),
        ("cubature_tets", ctypes.c_uint32),
        ("potential_evals", ctypes.c_uint32),
        ("contact_pairs", ctypes.c_uint32),
        ("contact_pairs_dropped", ctypes.c_uint32),
        ("budget_exceeded", ctypes.c_uint32),
        ("ms_world", ctypes.c_double),
        ("world_queries", ctypes.c_uint32),
        ("world_candidates", ctypes.c_uint32),
        ("world_contacts", ctypes.c_uint32),
    ]


class _WorldDef(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("max_colliders", ctypes.c_uint32),
        ("allocator", _Allocator),
        ("logger", _Logger),
    ]


class Transform(ctypes.Structure):
    """sinew_transform: x = R(rotation) y + position; rotation a quaternion w, x, y, z."""

    _fields_ = [("position", ctypes.c_float * 3), ("rotation", ctypes.c_float * 4)]


class _ColliderDef(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("shape", ctypes.c_int),
        ("normal", ctypes.c_float * 3),
        ("offset", ctypes.c_float),
        ("radius", ctypes.c_float),
        ("half_height", ctypes.c_float),
        ("half_extents", ctypes.c_float * 3),
        ("points", ctypes.POINTER(ctypes.c_float)),
        ("point_count", ctypes.c_uint32),
        ("vertices", ctypes.POINTER(ctypes.c_float)),
        ("vertex_count", ctypes.c_uint32),
        ("indices", ctypes.POINTER(ctypes.c_uint32)),
        ("triangle_count", ctypes.c_uint32),
        ("stiffness", ctypes.c_float),
        ("friction", ctypes.c_float),
        ("transform", Transform),
    ]


SHAPE_SPHERE, SHAPE_CAPSULE, SHAPE_MESH = 1, 2, 5


def find_library(path=""):
    """The libsinew.so to load: `path` when given, else $SINEW_LIB, else the system's."""
    for candidate in (path, os.environ.get("SINEW_LIB", "")):
        if candidate:
            if not os.path.isfile(candidate):
                raise SinewError(f"libsinew not found at {candidate}")
            return os.path.abspath(candidate)
    found = ctypes.util.find_library("sinew")
    if not found:
        raise SinewError(
            "libsinew.so not found: set the add-on's library path, or SINEW_LIB, "
            "to the libsinew.so a sinew build or install made"
        )
    return found


class Library:
    """A loaded libsinew.so with the signatures of the calls used here."""

    def __init__(self, path=""):
        self.path = find_library(path)
        try:
            lib = ctypes.CDLL(self.path)
        except OSError as e:
            raise SinewError(f"cannot load {self.path}: {e}") from e
        self.lib = lib
        vp, u32, i32, f32 = ctypes.c_void_p, ctypes.c_uint32, ctypes.c_int32, ctypes.c_float
        sig = {
            "sinew_result_string": (ctypes.c_char_p, [ctypes.c_int]),
            "sinew_blob_load": (ctypes.c_int, [ctypes.POINTER(_BlobDef), ctypes.POINTER(vp)]),
            "sinew_blob_destroy": (None, [vp]),
            "sinew_blob_bone_count": (u32, [vp]),
            "sinew_blob_surface_vertex_count": (u32, [vp]),
            "sinew_blob_surface_triangle_count": (u32, [vp]),
            "sinew_blob_surface_triangles": (ctypes.c_int, [vp, ctypes.POINTER(u32), u32]),
            "sinew_blob_bone_name": (ctypes.c_char_p, [vp, u32]),
            "sinew_blob_bone_bind": (ctypes.c_int, [vp, u32, ctypes.POINTER(ctypes.c_double)]),
            "sinew_blob_source_mesh_count": (u32, [vp]),
            "sinew_blob_output_sources": (ctypes.c_int, [vp, ctypes.POINTER(i32), u32]),
            "sinew_instance_create": (
                ctypes.c_int,
                [vp, ctypes.POINTER(_InstanceDef), ctypes.POINTER(vp)],
            ),
            "sinew_instance_destroy": (None, [vp]),
            "sinew_instance_reset": (ctypes.c_int, [vp]),
            "sinew_instance_set_pose": (ctypes.c_int, [vp, ctypes.POINTER(f32), u32]),
            "sinew_instance_mark_teleport": (ctypes.c_int, [vp]),
            "sinew_instance_step": (ctypes.c_int, [vp, f32]),
            "sinew_instance_read_surface": (
                ctypes.c_int,
                [vp, ctypes.POINTER(f32), ctypes.POINTER(f32), u32],
            ),
            "sinew_instance_get_stats": (ctypes.c_int, [vp, ctypes.POINTER(_StepStats)]),
            "sinew_world_create": (ctypes.c_int, [ctypes.POINTER(_WorldDef), ctypes.POINTER(vp)]),
            "sinew_world_destroy": (None, [vp]),
            "sinew_world_add_collider": (
                ctypes.c_int,
                [vp, ctypes.POINTER(_ColliderDef), ctypes.POINTER(u32)],
            ),
            "sinew_world_set_collider_transform": (ctypes.c_int, [vp, u32, ctypes.POINTER(Transform)]),
            "sinew_instance_set_world": (ctypes.c_int, [vp, vp]),
        }
        for name, (res, args) in sig.items():
            try:
                fn = getattr(lib, name)
            except AttributeError as e:
                raise SinewError(f"{self.path} has no {name}: an older libsinew?") from e
            fn.restype, fn.argtypes = res, args
            setattr(self, name[len("sinew_") :], fn)

    def result_string(self, r):
        return self.lib.sinew_result_string(r).decode()


class _Log:
    """Keeps the library's last error message, to say why a call failed."""

    def __init__(self):
        self.last = ""
        self.fn = _LOG_FN(self._log)  # referenced here so it outlives the C side's use

    def _log(self, level, message_id, message, user):
        if level == 0 and message:
            self.last = message.decode(errors="replace")

    def logger(self):
        return _Logger(self.fn, None, 1)


class Blob:
    """A loaded blob and what the add-on reads from it."""

    def __init__(self, lib, path):
        self.lib, self.path, self.log = lib, path, _Log()
        d = _BlobDef(ctypes.sizeof(_BlobDef), os.fsencode(path), None, 0, _Allocator(), self.log.logger())
        h = ctypes.c_void_p()
        r = lib.blob_load(ctypes.byref(d), ctypes.byref(h))
        if r != SINEW_OK:
            raise SinewError(f"cannot load the blob {path}: {self.log.last or lib.result_string(r)}")
        self.handle = h
        self.bone_count = lib.blob_bone_count(h)
        self.vertex_count = lib.blob_surface_vertex_count(h)

    def close(self):
        if self.handle:
            self.lib.blob_destroy(self.handle)
            self.handle = None

    def bone_names(self):
        names = [self.lib.blob_bone_name(self.handle, i) for i in range(self.bone_count)]
        if any(n is None for n in names):
            raise SinewError(f"{self.path} has no bone names: bake it again with this sinew")
        return [n.decode() for n in names]

    def bone_bind(self, bone):
        m = (ctypes.c_double * 12)()
        r = self.lib.blob_bone_bind(self.handle, bone, m)
        if r != SINEW_OK:
            raise SinewError(f"{self.path}: no bind pose for bone {bone} ({self.lib.result_string(r)})")
        return list(m)

    def output_sources(self):
        """(mesh, vertex) of each output vertex in the baked file; (-1, -1): none."""
        n = 2 * self.vertex_count
        pairs = (ctypes.c_int32 * n)()
        r = self.lib.blob_output_sources(self.handle, pairs, n)
        if r != SINEW_OK:
            raise SinewError(f"{self.path} has no output map ({self.lib.result_string(r)})")
        return [(pairs[2 * i], pairs[2 * i + 1]) for i in range(self.vertex_count)]

    def triangles(self):
        n = 3 * self.lib.blob_surface_triangle_count(self.handle)
        idx = (ctypes.c_uint32 * n)()
        self.lib.blob_surface_triangles(self.handle, idx, n)
        return list(idx)


class Instance:
    """One simulated character of a blob; poses and surfaces are ctypes float buffers
    (or anything exposing a writable float32 buffer of the right length)."""

    def __init__(self, blob, dynamic=False, patch_vertices=0):
        """patch_vertices: the budget of the full-space patch where the world presses the
        flesh beyond what the subspace holds (0: none)."""
        self.blob, self.lib = blob, blob.lib
        d = _InstanceDef(ctypes.sizeof(_InstanceDef), STEP_DYNAMIC if dynamic else STEP_QUASISTATIC, 0, _Allocator(), blob.log.logger())
        d.max_patch_vertices = patch_vertices
        h = ctypes.c_void_p()
        r = self.lib.instance_create(blob.handle, ctypes.byref(d), ctypes.byref(h))
        if r != SINEW_OK:
            raise SinewError(f"cannot create an instance: {blob.log.last or self.lib.result_string(r)}")
        self.handle = h
        self.stats = _StepStats()

    def close(self):
        if self.handle:
            self.lib.instance_destroy(self.handle)
            self.handle = None

    def reset(self):
        self._check(self.lib.instance_reset(self.handle), "reset")

    def mark_teleport(self):
        self._check(self.lib.instance_mark_teleport(self.handle), "mark_teleport")

    def set_pose(self, transforms):
        """transforms: bone_count * 12 float32 (3x3 row-major, then the translation)."""
        p = _float_ptr(transforms, 12 * self.blob.bone_count)
        self._check(self.lib.instance_set_pose(self.handle, p, self.blob.bone_count), "set_pose")

    def step(self, dt):
        """Steps; returns the step's status flags (a failed step is not an exception: the
        library undid it and the surface stays valid)."""
        self.lib.instance_step(self.handle, dt)
        self.stats.struct_size = ctypes.sizeof(_StepStats)
        self.lib.instance_get_stats(self.handle, ctypes.byref(self.stats))
        return self.stats.status

    def set_world(self, world):
        self._check(self.lib.instance_set_world(self.handle, world.handle if world else None), "set_world")

    def read_surface(self, positions):
        p = _float_ptr(positions, 3 * self.blob.vertex_count)
        self._check(self.lib.instance_read_surface(self.handle, p, None, self.blob.vertex_count), "read_surface")

    def _check(self, r, what):
        if r != SINEW_OK:
            raise SinewError(f"{what}: {self.blob.log.last or self.lib.result_string(r)}")


class World:
    """A collision world: spheres, capsules and triangle meshes the flesh collides with,
    in the blob's space (the add-on leaves the actor at the identity)."""

    def __init__(self, lib):
        self.lib, self.log = lib, _Log()
        d = _WorldDef(ctypes.sizeof(_WorldDef), 0, _Allocator(), self.log.logger())
        h = ctypes.c_void_p()
        r = lib.world_create(ctypes.byref(d), ctypes.byref(h))
        if r != SINEW_OK:
            raise SinewError(f"cannot create a collision world: {self.log.last or lib.result_string(r)}")
        self.handle = h

    def close(self):
        if self.handle:
            self.lib.world_destroy(self.handle)
            self.handle = None

    def add(self, shape, transform, radius=0.0, half_height=0.0, vertices=None, indices=None, friction=0.0):
        """Adds a collider (SHAPE_SPHERE, _CAPSULE or _MESH: flat float xyz and uint32
        triangle lists, copied by the library) and returns its id."""
        d = _ColliderDef()
        d.struct_size, d.shape = ctypes.sizeof(_ColliderDef), shape
        d.radius, d.half_height, d.friction, d.transform = radius, half_height, friction, transform
        if shape == SHAPE_MESH:
            v = (ctypes.c_float * len(vertices))(*vertices)
            t = (ctypes.c_uint32 * len(indices))(*indices)
            d.vertices, d.vertex_count = v, len(vertices) // 3
            d.indices, d.triangle_count = t, len(indices) // 3
        cid = ctypes.c_uint32()
        r = self.lib.world_add_collider(self.handle, ctypes.byref(d), ctypes.byref(cid))
        if r != SINEW_OK:
            raise SinewError(f"collider refused: {self.log.last or self.lib.result_string(r)}")
        return cid.value

    def move(self, cid, transform):
        r = self.lib.world_set_collider_transform(self.handle, cid, ctypes.byref(transform))
        if r != SINEW_OK:
            raise SinewError(f"collider transform refused: {self.log.last or self.lib.result_string(r)}")


def _float_ptr(buf, count):
    """A float* into `buf` (a ctypes array or a contiguous float32 buffer such as a numpy
    array), after checking it holds `count` floats."""
    if isinstance(buf, ctypes.Array):
        if len(buf) < count:
            raise SinewError(f"buffer of {len(buf)} floats, {count} needed")
        return ctypes.cast(buf, ctypes.POINTER(ctypes.c_float))
    mv = memoryview(buf)
    if mv.format != "f" or mv.nbytes < 4 * count or not mv.c_contiguous:
        raise SinewError(f"need a contiguous float32 buffer of {count} floats")
    return ctypes.cast((ctypes.c_float * count).from_buffer(mv), ctypes.POINTER(ctypes.c_float))
