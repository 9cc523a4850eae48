"""A Scene as flat arrays for the compiled engine, or the reason it cannot be.

The compiled engine renders every shape of the registry (rtcli/shapes/), each with
any transform; checker and image textures; point, spot and area lights. A CSG has no
kernels and keeps the numpy engine: `unsupported(scene)` names it.

Geometry (`Geometry`), one row per scene object:
- `objects` (N, SHAPE_WIDTH): the shape's row (rtcli/shapes/, its own layout);
- `ints` (N, 4), by the names KIND (the shape's place in the registry), XFORM (its
  row of `transforms`, -1 for none), CASTS (its material casts shadows) and MATERIAL;
- `transforms` (T, 36): the packed transforms (rtcli/core/transform.py) of the
  objects that have one, so that a scene of a million plain spheres pays nothing;
- `listed`: the objects tested one by one: the unbounded ones (planes), or, as the
  numpy engine does for a scene without a BVH (Scene.wants_bvh: fewer than 8
  bounded objects, or --no-bvh), every object in file order, so that ties go the
  same way;
- `nodes`, `links`, `perm`: BVH trees one after another (rtcli/core/bvh.py's layout),
  the scene's over the other objects first (root 0), then each mesh's over its faces;
- `pool`: the rows shapes own (polygon vertices, triangles); a shape's row says where
  its own start (FIRST_COLUMN) and a mesh's where its tree's root is (ROOT_COLUMN).

Looks (`Looks`): the MaterialTable's arrays under the names the shading kernels read
(rtcli/core/shading.py), its texture rows and texels, the lights' rows and sample
counts, and the scene constants.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rtcli.core.bvh import BVH
from rtcli.core.scene import object_tree
from rtcli.core.transform import PACKED
from rtcli.shapes import SHAPES
from rtcli.shapes.base import POOL_WIDTH

SHAPE_WIDTH = 20                                   # columns of an object row: the widest shape's row
KIND, XFORM, CASTS, MATERIAL = range(4)            # columns of ints
KINDS = {cls: k for k, cls in enumerate(SHAPES.values())}

# Few arrays on purpose: numba passes each array argument as several machine words.
Geometry = namedtuple("Geometry", "objects ints transforms listed nodes links perm pool")
Looks = namedtuple("Looks", "ka kd ks shininess emission kr kt ior shiny mirror clear fresnel filters texture "
                            "texels lights samples ambient background offset max_depth blinn medium_ior "
                            "reflect_tir any_filter")


def unsupported(scene) -> str | None:
    """Why the compiled engine cannot render `scene`, or None when it can."""
    for o in scene.objects:
        if type(o.shape) not in KINDS:
            return f"{o.kind or type(o.shape).__name__} objects"
    return None


class _Trees:
    """BVH trees one after another: rows of `nodes` and `links` (with absolute child and
    perm indices), and the leaves' entries in `perm` (objects, or triangles of the pool)."""

    def __init__(self):
        self.nodes, self.links, self.perm, self.n_nodes, self.n_perm = [], [], [], 0, 0

    def add(self, bvh: BVH, entries: np.ndarray) -> int:
        """Append a tree whose leaves hold entries[bvh.perm]; returns its root."""
        root = self.n_nodes
        links = bvh.links.copy()
        links[:, 0] = np.where(links[:, 0] >= 0, links[:, 0] + root, -1)
        links[:, 1] += self.n_perm
        self.nodes.append(bvh.nodes)
        self.links.append(links)
        self.perm.append(np.asarray(entries, dtype=np.int64)[bvh.perm])
        self.n_perm += len(bvh.perm)
        self.n_nodes += len(bvh.nodes)
        return root

    def arrays(self):
        return (np.ascontiguousarray(np.concatenate(self.nodes)), np.ascontiguousarray(np.concatenate(self.links)),
                np.concatenate(self.perm).astype(np.int64))


def geometry(scene, tree: bool, bvh: tuple | None = None) -> tuple[Geometry, int]:
    """The scene's geometry, and the traversal stack it needs (the scene's tree, then a mesh's).
    Without `tree` every object is listed, in file order; `bvh`: object_tree's, if made already."""
    n = len(scene.objects)
    objects, ints = np.zeros((n, SHAPE_WIDTH)), np.zeros((n, 4), dtype=np.int64)
    bounded = scene.boxes.bounded
    listed = np.flatnonzero(~bounded | (not tree))
    members, scene_bvh = (bvh or object_tree(scene)) if tree else (np.zeros(0, np.int64), BVH(np.zeros((0, 3)),
                                                                                             np.zeros((0, 3))))
    trees, mesh_depth, transforms = _Trees(), 0, []
    trees.add(scene_bvh, members)                    # root 0
    pool, n_pool = [np.zeros((0, POOL_WIDTH))], 0
    for k, o in enumerate(scene.objects):
        shape = o.shape
        row = np.array(shape.row, dtype=float)
        if shape.FIRST_COLUMN is not None:
            row[shape.FIRST_COLUMN] = n_pool
        if shape.ROOT_COLUMN is not None:
            row[shape.ROOT_COLUMN] = trees.add(shape.bvh, np.arange(len(shape.pool)) + n_pool)
            mesh_depth = max(mesh_depth, shape.bvh.depth)
        if len(row) > SHAPE_WIDTH:
            raise ValueError(f"a {type(shape).__name__} row is wider than {SHAPE_WIDTH} columns")
        objects[k, :len(row)] = row
        if len(shape.pool):
            pool.append(shape.pool)
            n_pool += len(shape.pool)
        if o.transform is not None:
            transforms.append(o.transform)
        ints[k] = KINDS[type(shape)], len(transforms) - 1 if o.transform is not None else -1, \
            scene.materials.shadow[o.material], o.material
    geo = Geometry(objects, ints, np.array(transforms).reshape(-1, PACKED), listed.astype(np.int64),
                   *trees.arrays(), np.ascontiguousarray(np.concatenate(pool)))
    return geo, scene_bvh.depth + mesh_depth + 4


def mesh_geometry(mesh) -> Geometry:
    """One mesh's faces and tree (root 0) as a Geometry, for the compiled walk over its triangles."""
    none = np.zeros(0, dtype=np.int64)
    return Geometry(np.zeros((0, SHAPE_WIDTH)), np.zeros((0, 4), dtype=np.int64), np.zeros((0, PACKED)), none,
                    mesh.bvh.nodes, mesh.bvh.links, mesh.bvh.perm, np.ascontiguousarray(mesh.pool))


def looks(scene) -> Looks:
    table = scene.materials
    samples = np.array([light.samples for light in scene.lights], dtype=np.int64)
    return Looks(table.ka, table.kd, table.ks, table.shininess, table.emission, table.kr, table.kt, table.ior,
                 table.shiny.astype(np.int64), table.mirror.astype(np.int64), table.clear.astype(np.int64),
                 table.fresnel, table.filters.astype(np.int64), table.texture, table.texels, scene.light_rows,
                 samples, np.asarray(scene.ambient, float), np.asarray(scene.background, float),
                 float(scene.offset), int(scene.settings.max_depth), scene.settings.specular == "blinn",
                 float(scene.settings.medium_ior), scene.settings.total_internal_reflection == "reflect",
                 bool(table.filters.any()))
