"""A Scene as flat arrays for the compiled path, or the reason it cannot be.

The compiled integrator handles the shapes most scenes are made of: spheres,
planes, boxes, cylinders, cones, triangles, squares, polygons and triangle
meshes (flat or smooth), each with any transform; checker and image textures;
point, spot and area lights. Anything else (CSG, torus) keeps the numpy path:
`unsupported(scene)` names the first such thing.

Geometry (`Geometry`): one row per scene object (see shapes.py for the row
layout); the objects tested one by one (`listed`), the unbounded ones (planes),
with a BVH over the bounded ones; or, as the numpy core does for a scene without
an Accelerator (fewer than 8 bounded objects), every object in file order, so
that ties go the same way. Meshes put their triangles and BVH nodes in shared arrays, polygons their
vertices; an object's integers say where its own start. Looks (`Looks`): the
MaterialTable's arrays, each material's texture (image textures put their
texels in one shared array), the lights and the scene constants.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rtcli.core.bvh import BVH
from rtcli.core.textures import Checker, ImageTexture
from rtcli.shapes.box import Box
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.planar import Plane, Polygon, Square, Triangle
from rtcli.shapes.quadric import _Tapered
from rtcli.shapes.sphere import Sphere

SPHERE, PLANE, BOX, TAPERED, TRIANGLE, SQUARE, MESH, POLYGON = range(8)    # shape kinds, as in shapes.py
INV, NRM, WIDTH = 24, 36, 48                        # columns of an object row: parameters, object_from_world, A^-T
KIND, XF, CASTS, ROOT, SMOOTH = range(5)            # columns of an object's integers
POOL = 27                                           # pool rows: a triangle's a, e1, e2, face, corner normals, uvs

# Few arrays on purpose: numba passes each array as ~8 machine words per call.
# pool: the triangles of every mesh, then the vertices of every polygon (x, y, z in a row).
Geometry = namedtuple("Geometry", "objects ints listed nodes links perm pool")
# word, bits: a float64 scratch cell and its uint64 view, for hashing a float's bits (jitter).
Looks = namedtuple("Looks", "material ka kd ks emission kr kt shininess ior shiny mirror clear "
                            "texture texels lights ambient background offset max_depth blinn word bits")
NO_TEXTURE, CHECKER, IMAGE = 0, 1, 2                # texture rows: kind, 1 / size, color1, color2, and for
                                                    # images: first texel, width, height, repeat


def unsupported(scene) -> str | None:
    """Why the compiled path cannot render `scene`, or None when it can."""
    for o in scene.objects:
        if not isinstance(o.shape, (Sphere, Plane, Box, _Tapered, Mesh, Triangle, Square, Polygon)):
            return f"{o.kind or type(o.shape).__name__} objects"
    return None


def _row(shape) -> tuple[int, list]:
    """(kind, parameters) of one analytic shape."""
    if isinstance(shape, Sphere):
        return SPHERE, [*shape.center, shape.radius, shape.radius ** 2]
    if isinstance(shape, Plane):
        return PLANE, [*shape.point, *shape.n, *shape.e1, *shape.e2]
    if isinstance(shape, Box):
        return BOX, [*shape.lo, *shape.hi]
    if isinstance(shape, Square):
        return SQUARE, []
    if isinstance(shape, Triangle):
        smooth = shape.normals is not None
        corners = shape.normals.ravel() if smooth else np.zeros(9)
        return TRIANGLE, [*shape.a, *shape.e1, *shape.e2, *shape.face, *corners, float(smooth)]
    s = shape
    return TAPERED, [*s.base, *s.e1, *s.e2, *s.a, s.r, s.h, s.s0, s.s1, float(s.capped)]


class _Trees:
    """BVH nodes, one tree after another: rows (lo, hi) in `nodes`, (child, start, count) in
    `links` with absolute indices, leaves' entries in `perm` (objects or triangles)."""

    def __init__(self):
        self.nodes, self.links, self.perm, self.n_nodes, self.n_perm = [], [], [], 0, 0

    def add(self, bvh: BVH, entries: np.ndarray) -> int:
        """Append a tree whose leaves hold entries[bvh.perm]; returns its root."""
        root = self.n_nodes
        if bvh.m == 0:                               # an empty tree: one leaf holding nothing
            self.nodes.append(np.zeros((1, 6)))
            self.links.append(np.array([[-1, 0, 0]]))
        else:
            self.nodes.append(np.concatenate([bvh.lo.T, bvh.hi.T], axis=1))
            child = np.where(bvh.child >= 0, bvh.child + root, -1)
            self.links.append(np.stack([child, bvh.start + self.n_perm, bvh.count], axis=1))
            self.perm.append(entries[bvh.perm])
            self.n_perm += bvh.m
        self.n_nodes += len(self.nodes[-1])
        return root

    def arrays(self):
        perm = np.concatenate(self.perm) if self.perm else np.zeros(0)
        return (np.ascontiguousarray(np.concatenate(self.nodes)), np.ascontiguousarray(np.concatenate(self.links)),
                perm.astype(np.int64))


def geometry(scene) -> tuple[Geometry, int]:
    """The scene's geometry, and the traversal stack size it needs (scene tree, then a mesh's)."""
    n = len(scene.objects)
    objects, ints = np.zeros((n, WIDTH)), np.zeros((n, 5), dtype=np.int64)
    boxes = scene.boxes
    tree = scene.accel is not None                   # else every object is listed, in file order
    listed = [k for k, b in enumerate(boxes) if b is None or not tree]
    members = np.array([k for k, b in enumerate(boxes) if b is not None and tree], dtype=np.int64)
    trees, mesh_depth = _Trees(), 0
    scene_bvh = BVH(np.array([boxes[k][0] for k in members]).reshape(-1, 3),
                    np.array([boxes[k][1] for k in members]).reshape(-1, 3), leaf_size=2)
    trees.add(scene_bvh, members)                    # root 0
    pool = [np.zeros((0, POOL))]
    n_pool = 0
    for k, o in enumerate(scene.objects):
        shape = o.shape
        if isinstance(shape, Mesh):
            corners = shape.normal_corners
            ints[k, KIND], ints[k, SMOOTH] = MESH, corners is not None
            ints[k, ROOT] = trees.add(shape.bvh, np.arange(len(shape.a)) + n_pool)
            corners = np.zeros((len(shape.a), 9)) if corners is None else corners.reshape(-1, 9)
            uvs = np.full((len(shape.a), 6), np.nan) if shape.uv_corners is None else shape.uv_corners.reshape(-1, 6)
            pool.append(np.concatenate([shape.a, shape.e1, shape.e2, shape.face, corners, uvs], axis=1))
            mesh_depth = max(mesh_depth, shape.bvh.depth)
        elif isinstance(shape, Polygon):             # plane point and normal, projection axes, its vertices
            ints[k, KIND], ints[k, ROOT] = POLYGON, n_pool
            objects[k, :15] = [*shape.v[0], *shape.n, *shape.axes, len(shape.v), *shape.e1, *shape.e2]
            pool.append(np.concatenate([shape.v, np.zeros((len(shape.v), POOL - 3))], axis=1))
        else:
            ints[k, KIND], row = _row(shape)
            objects[k, :len(row)] = row
        n_pool += len(pool[-1])
        if o.world_from_object is not None:
            ints[k, XF] = 1
            objects[k, INV:INV + 12] = o.world_from_object.m_inv[:3, :].ravel()
            objects[k, NRM:NRM + 12] = np.concatenate([o.world_from_object.m_inv[:3, :3].T, np.zeros((3, 1))],
                                                      axis=1).ravel()
    ints[:, CASTS] = scene.materials.shadow[[o.material for o in scene.objects]]
    geo = Geometry(objects, ints, np.array(listed, dtype=np.int64), *trees.arrays(),
                   np.ascontiguousarray(np.concatenate(pool)))
    return geo, scene_bvh.depth + mesh_depth + 4


def looks(scene) -> Looks:
    table = scene.materials
    texture, texels = np.zeros((len(table), 12)), [np.zeros((0, 3))]
    for k, m in enumerate(table.materials):
        if isinstance(m.texture, Checker):
            texture[k, :8] = [CHECKER, 1 / m.texture.size, *m.texture.color1, *m.texture.color2]
        elif isinstance(m.texture, ImageTexture):
            h, w, _ = m.texture.texels.shape
            texture[k] = [IMAGE, 0, 0, 0, 0, 0, 0, 0, sum(map(len, texels)), w, h, float(m.texture.repeat)]
            texels.append(m.texture.texels.reshape(-1, 3))
    lights = np.zeros((len(scene.lights), 22))      # position, color, attenuation, spot axis, cos, falloff,
    for k, light in enumerate(scene.lights):        # spot?, area u, v, n (0: a point light)
        spot, area = light.spot_direction is not None, light.area_u is not None
        axis = light.spot_direction if spot else np.zeros(3)
        u, v = (light.area_u, light.area_v) if area else (np.zeros(3), np.zeros(3))
        lights[k] = [*light.position, *light.color, *light.attenuation, *axis,
                     light.spot_cos, light.spot_falloff, float(spot), *u, *v, light.area_samples if area else 0]
    material = np.array([o.material for o in scene.objects], dtype=np.int64)
    word = np.zeros(1)
    return Looks(material, table.ka, table.kd, table.ks, table.emission, table.kr, table.kt, table.n, table.ior,
                 table.shiny.astype(np.int64), table.mirror.astype(np.int64), table.clear.astype(np.int64),
                 texture, np.ascontiguousarray(np.concatenate(texels), dtype=float), lights, np.asarray(scene.ambient, float), np.asarray(scene.background, float),
                 float(scene.offset), int(scene.settings.max_depth), int(scene.settings.specular == "blinn"),
                 word, word.view(np.uint64))
