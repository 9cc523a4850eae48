"""A Scene as flat arrays for the compiled path, or the reason it cannot be.

The compiled integrator handles the shapes most scenes are made of: spheres,
planes, boxes, cylinders, cones and triangle meshes, each with any transform;
materials with no texture or a checker; point and spot lights. Anything else
(CSG, torus, single triangles, polygons, squares, image textures, area lights)
keeps the numpy path: `unsupported(scene)` names the first such thing.

Geometry (`Geometry`): one row per scene object (see shapes.py for the row
layout), the unbounded objects (planes) by index, and a BVH over the bounded
ones. Meshes put their triangles and BVH nodes in shared arrays; a mesh row's
par holds its root node. Looks (`Looks`): the MaterialTable's arrays, the
checker of each material, the lights and the scene constants.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rtcli.bvh import BVH
from rtcli.shapes.box import Box
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.planar import Plane
from rtcli.shapes.quadric import _Tapered
from rtcli.shapes.sphere import Sphere
from rtcli.textures import Checker

SPHERE, PLANE, BOX, TAPERED, MESH = range(5)        # shape kinds, as in shapes.py
INV, NRM, WIDTH = 20, 32, 44                        # columns of an object row: parameters, object_from_world, A^-T
KIND, XF, CASTS, ROOT = range(4)                    # columns of an object's integers

# Few arrays on purpose: numba passes each array as ~8 machine words per call.
Geometry = namedtuple("Geometry", "objects ints unbounded nodes links perm tris")
Looks = namedtuple("Looks", "material ka kd ks emission kr kt shininess ior shiny mirror clear "
                            "checker lights ambient background offset max_depth blinn")


def unsupported(scene) -> str | None:
    """Why the compiled path cannot render `scene`, or None when it can."""
    for o in scene.objects:
        if not isinstance(o.shape, (Sphere, Plane, Box, _Tapered, Mesh)):
            return f"{o.kind or type(o.shape).__name__} objects"
        if isinstance(o.shape, Mesh) and o.shape.normal_corners is not None:
            return "smooth meshes"
    for m in scene.materials.materials:
        if m.texture is not None and not isinstance(m.texture, Checker):
            return "image textures"
    for light in scene.lights:
        if light.area_u is not None:
            return "area lights"
    return None


def _row(shape) -> tuple[int, list]:
    """(kind, parameters) of one analytic shape."""
    if isinstance(shape, Sphere):
        return SPHERE, [*shape.center, shape.radius, shape.radius ** 2]
    if isinstance(shape, Plane):
        return PLANE, [*shape.point, *shape.n]
    if isinstance(shape, Box):
        return BOX, [*shape.lo, *shape.hi]
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
    objects, ints = np.zeros((n, WIDTH)), np.zeros((n, 4), dtype=np.int64)
    boxes = scene.boxes
    members = np.array([k for k, b in enumerate(boxes) if b is not None], dtype=np.int64)
    trees, tris, n_tris, mesh_depth = _Trees(), [np.zeros((0, 12))], 0, 0
    scene_bvh = BVH(np.array([boxes[k][0] for k in members]).reshape(-1, 3),
                    np.array([boxes[k][1] for k in members]).reshape(-1, 3), leaf_size=2)
    trees.add(scene_bvh, members)                    # root 0
    for k, o in enumerate(scene.objects):
        if isinstance(o.shape, Mesh):
            m = o.shape
            ints[k, KIND], ints[k, ROOT] = MESH, trees.add(m.bvh, np.arange(len(m.a)) + n_tris)
            tris.append(np.concatenate([m.a, m.e1, m.e2, m.face], axis=1))
            n_tris, mesh_depth = n_tris + len(m.a), max(mesh_depth, m.bvh.depth)
        else:
            ints[k, KIND], row = _row(o.shape)
            objects[k, :len(row)] = row
        if o.world_from_object is not None:
            ints[k, XF] = 1
            objects[k, INV:INV + 12] = o.world_from_object.m_inv[:3, :].ravel()
            objects[k, NRM:NRM + 12] = np.concatenate([o.world_from_object.m_inv[:3, :3].T, np.zeros((3, 1))],
                                                      axis=1).ravel()
    ints[:, CASTS] = scene.materials.shadow[[o.material for o in scene.objects]]
    unbounded = np.array([k for k, b in enumerate(boxes) if b is None], dtype=np.int64)
    geo = Geometry(objects, ints, unbounded, *trees.arrays(), np.ascontiguousarray(np.concatenate(tris)))
    return geo, scene_bvh.depth + mesh_depth + 4


def looks(scene) -> Looks:
    table = scene.materials
    checker = np.zeros((len(table), 8))             # textured?, 1 / size, color1, color2
    for k, m in enumerate(table.materials):
        if m.texture is not None:
            checker[k] = [1.0, 1 / m.texture.size, *m.texture.color1, *m.texture.color2]
    lights = np.zeros((len(scene.lights), 15))      # position, color, attenuation, spot axis, cos, falloff, spot?
    for k, light in enumerate(scene.lights):
        spot = light.spot_direction is not None
        axis = light.spot_direction if spot else np.zeros(3)
        lights[k] = [*light.position, *light.color, *light.attenuation, *axis,
                     light.spot_cos, light.spot_falloff, float(spot)]
    material = np.array([o.material for o in scene.objects], dtype=np.int64)
    return Looks(material, table.ka, table.kd, table.ks, table.emission, table.kr, table.kt, table.n, table.ior,
                 table.shiny.astype(np.int64), table.mirror.astype(np.int64), table.clear.astype(np.int64),
                 checker, lights, np.asarray(scene.ambient, float), np.asarray(scene.background, float),
                 float(scene.offset), int(scene.settings.max_depth), int(scene.settings.specular == "blinn"))
