"""A Scene as flat arrays for the compiled engine, or the reason it cannot be.

The compiled engine renders every shape of the registry (rtcli/shapes/), each with
any transform; checker and image textures; point, spot and area lights. A CSG has no
kernels and keeps the numpy engine: `unsupported(scene)` names it.

Geometry (`Geometry`), one row per scene object:
- `objects` (N, OBJECT_WIDTH): the shape's row (rtcli/shapes/, its own layout) from
  column SHAPE, then its packed transform (rtcli/core/transform.py) from XFORM;
- `ints` (N, 4), by the names KIND (the shape's place in the registry), TRANSFORMED,
  CASTS (its material casts shadows) and MATERIAL;
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
from rtcli.core.transform import PACKED
from rtcli.shapes import SHAPES
from rtcli.shapes.base import POOL_WIDTH

SHAPE, XFORM = 0, 24                               # columns of an object row: the shape's row, its transform
OBJECT_WIDTH = XFORM + PACKED
KIND, TRANSFORMED, CASTS, MATERIAL = range(4)      # columns of ints
KINDS = {cls: k for k, cls in enumerate(SHAPES.values())}

# Few arrays on purpose: numba passes each array argument as several machine words.
Geometry = namedtuple("Geometry", "objects ints listed nodes links perm pool")
Looks = namedtuple("Looks", "ka kd ks shininess emission kr kt ior shiny mirror clear texture texels "
                            "lights samples ambient background offset max_depth blinn")


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


def geometry(scene, tree: bool) -> tuple[Geometry, int]:
    """The scene's geometry, and the traversal stack it needs (the scene's tree, then a mesh's).
    Without `tree` every object is listed, in file order."""
    n = len(scene.objects)
    objects, ints = np.zeros((n, OBJECT_WIDTH)), np.zeros((n, 4), dtype=np.int64)
    boxes = scene.boxes
    listed = [k for k, b in enumerate(boxes) if b is None or not tree]
    members = np.array([k for k, b in enumerate(boxes) if b is not None and tree], dtype=np.int64)
    trees, mesh_depth = _Trees(), 0
    scene_bvh = BVH(np.array([boxes[k][0] for k in members]).reshape(-1, 3),
                    np.array([boxes[k][1] for k in members]).reshape(-1, 3), leaf_size=2)
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
        if len(row) > XFORM:
            raise ValueError(f"a {type(shape).__name__} row is wider than {XFORM} columns")
        objects[k, SHAPE:SHAPE + len(row)] = row
        pool.append(shape.pool)
        n_pool += len(shape.pool)
        if o.transform is not None:
            objects[k, XFORM:] = o.transform
        ints[k] = KINDS[type(shape)], o.transform is not None, scene.materials.shadow[o.material], o.material
    geo = Geometry(objects, ints, np.array(listed, dtype=np.int64), *trees.arrays(),
                   np.ascontiguousarray(np.concatenate(pool)))
    return geo, scene_bvh.depth + mesh_depth + 4


def mesh_geometry(mesh) -> Geometry:
    """One mesh's faces and tree (root 0) as a Geometry, for the compiled walk over its triangles."""
    none = np.zeros(0, dtype=np.int64)
    return Geometry(np.zeros((0, OBJECT_WIDTH)), np.zeros((0, 4), dtype=np.int64), none, mesh.bvh.nodes,
                    mesh.bvh.links, mesh.bvh.perm, np.ascontiguousarray(mesh.pool))


def looks(scene) -> Looks:
    table = scene.materials
    samples = np.array([light.samples for light in scene.lights], dtype=np.int64)
    return Looks(table.ka, table.kd, table.ks, table.shininess, table.emission, table.kr, table.kt, table.ior,
                 table.shiny.astype(np.int64), table.mirror.astype(np.int64), table.clear.astype(np.int64),
                 table.texture, table.texels, scene.light_rows, samples, np.asarray(scene.ambient, float),
                 np.asarray(scene.background, float), float(scene.offset), int(scene.settings.max_depth),
                 scene.settings.specular == "blinn")
