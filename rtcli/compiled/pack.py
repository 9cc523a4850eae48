"""A Scene as flat arrays for the compiled engine, or the reason it cannot be.

The compiled engine renders every shape of the registry (rtcli/shapes/), each with
any transform, and CSG; checker and image textures; point, spot and area lights.

Geometry (`Geometry`), one row per scene object:
- `objects` (N + L, SHAPE_WIDTH): the shape's row (rtcli/shapes/, its own layout), or
  a csg's (the columns PROGRAM ... HI below); then the shape rows of the L csg leaves;
- `ints` (N, 4), by the names KIND (the shape's place in the registry, CSG_KIND for a
  csg), XFORM (its row of `transforms`, -1 for none), CASTS (its material casts
  shadows) and MATERIAL;
- `transforms` (T, 36): the packed transforms (rtcli/core/transform.py) of the
  objects that have one, so that a scene of a million plain spheres pays nothing, and
  of the csg children that have one;
- `listed`: the objects tested one by one: the unbounded ones (planes), or, as the
  numpy engine does for a scene without a BVH (Scene.wants_bvh: fewer than 8
  bounded objects, or --no-bvh), every object in file order, so that ties go the
  same way;
- `nodes`, `links`, `perm`: BVH trees one after another (rtcli/core/bvh.py's layout),
  the scene's over the other objects first (root 0), then each mesh's over its faces;
- `pool`: the rows shapes own (polygon vertices, triangles); a shape's row says where
  its own start (FIRST_COLUMN) and a mesh's where its tree's root is (ROOT_COLUMN);
- `program` (P, 2): each csg's tree as a postfix program, one after another: (LEAF, l)
  puts leaf l's spans on the stack, (op, n) (csg.UNION, INTERSECTION, DIFFERENCE)
  replaces the top n span lists by their combination;
- `leaves` (L, 4 + 2 D): each csg leaf's KIND, ROW (its shape row in `objects`), DEPTH
  (the csg children on its path from the csg), MATERIAL, then for each of those children,
  outermost first, its transform (-1: none) and FLIP (-1 for a difference's later
  child, else 1). A csg hit's prim is leaf + L x (the leaf's surface).

Looks (`Looks`): the MaterialTable's arrays under the names the shading kernels read
(rtcli/core/shading.py), its texture rows and texels, the lights' rows and sample
counts, and the scene constants.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from rtcli.core.bvh import BVH, padded
from rtcli.core.objects import singles, sphere_blocks
from rtcli.core.scene import object_tree
from rtcli.core.transform import PACKED
from rtcli.shapes import SHAPES
from rtcli.shapes.base import POOL_WIDTH
from rtcli.shapes.csg import CSG, OPS
from rtcli.shapes.sphere import Sphere

SHAPE_WIDTH = 20                                   # columns of an object row: the widest shape's row
KIND, XFORM, CASTS, MATERIAL = range(4)            # columns of ints
KINDS = {cls: k for k, cls in enumerate(SHAPES.values())}
CSG_KIND = len(KINDS)
SMOOTH_KINDS = (KINDS[SHAPES["triangle"]], KINDS[SHAPES["mesh"]])     # shapes with a shadow-terminator shift
# A csg's row: where its program starts and how long it is, its leaf count, how many spans its
# leaves can give (SPANS: the capacity of its span lists), its largest number of children, its
# scratch (in the traversal stack), and its object-space box (BOUNDED 0: none).
PROGRAM, LENGTH, LEAF_COUNT, SPANS, CHILDREN, SCRATCH, BOUNDED, LO, HI = 0, 1, 2, 3, 4, 5, 6, 7, 10
LEAF = len(OPS)                                    # the program's code for a leaf (the ops are csg's)
ROW, DEPTH, PATH = 1, 2, 4                         # columns of leaves (KIND and MATERIAL as in ints)

# The integrator's frames (compiled/integrator.py), one per depth, then one per lane of a packet
# (the primary hits). A frame: the local color so far, the hit point p, the facing shading normal n
# and geometric normal ng, the unit direction D of the ray that hit, entering (1 or 0), the
# material, which secondary ray comes next (STAGE: 0 the mirror ray, 1 the refracted ray, 2 done),
# the weights of the mirror and refracted rays, the refracted direction, the path weight of the ray
# that hit (adc_bailout's, wavefront/trace.py), the texture's color T at the hit, where its shadow
# feelers leave from (less the offset), the lights whose feeler a packet has traced (FEELERS, a
# bit a light) and those it found blocked (BLOCKED), and the media the ray is in: how many, then
# their iors (max_depth slots from MEDIA_IOR on).
(COLOR_SUM, P, N, NG, D, ENTERING, MATERIAL_OF, STAGE, W_REFLECT, W_REFRACT, REFRACTED_DIR, PATH_WEIGHT, TEXTURE,
 BASE, FEELERS, BLOCKED, MEDIA_COUNT, MEDIA_IOR) = (0, 3, 6, 9, 12, 15, 16, 17, 18, 21, 24, 27, 30, 33, 36, 37, 38, 39)
PACKED_LIGHTS = 50                                  # lights whose feelers packets trace (bits of a float)

# A packet's scratch (compiled/packets.py), `lanes` (ROWS, W): one column per ray. Its rows: two
# blocks of rays (origin, direction, 1 / direction), the world rays and the rays in the space of the
# mesh being walked; each lane's interval; answers (t, entry, prim) of the scene tree's walk, of a
# mesh tree's walk and of the listed objects (in the end, of the whole scene).
W = 8                                               # lanes: 8 float64, one AVX-512 register
OX, OY, OZ, DX, DY, DZ, IX, IY, IZ = range(9)      # a block of rays
WORLD_RAYS, OBJECT_RAYS, T_MIN, T_MAX, TREE, MESH, LISTED, ROWS = 0, 9, 18, 19, 20, 23, 26, 29
BEST, WON, PRIM = range(3)                          # an answer's rows

# Few arrays on purpose: numba passes each array argument as several machine words.
Geometry = namedtuple("Geometry", "objects ints transforms listed nodes links perm pool program leaves")
Looks = namedtuple("Looks", "ka kd ks shininess emission kr kt ior shiny mirror clear fresnel filters texture "
                            "texels lights samples ambient background offset max_depth blinn medium_ior "
                            "reflect_tir any_filter terminator adc_bailout")


def unsupported(scene) -> str | None:
    """Why the compiled engine cannot render `scene`, or None when it can."""
    for _, o in singles(scene.objects):                 # a block's spheres are supported
        if type(o.shape) not in KINDS and not isinstance(o.shape, CSG):
            return f"{o.kind or type(o.shape).__name__} objects"
    return None


def scratch(leaves: int, spans: int, children: int) -> int:
    """Words of the traversal stack a csg's evaluation takes (query.csg_spans lays them out): a
    start and length per span list (at most one list per leaf), two boundaries per span in the
    lists and again among the sorted boundaries, with each boundary's t, leaf and surface (and
    direction and child when sorted), and a count per child."""
    return 2 * leaves + 4 * spans + 8 * spans + children


class _CSGs:
    """The csg objects' programs and leaves, as packed rows."""

    def __init__(self, first_row: int):
        self.program, self.leaves, self.rows, self.first_row = [], [], [], first_row

    def add(self, csg: CSG, transforms: list) -> np.ndarray:
        """Append csg's program and leaves (their transforms to `transforms`); its object row."""
        start, first_leaf = len(self.program), len(self.leaves)
        children = self._emit(csg, (), transforms)
        leaves = len(self.leaves) - first_leaf
        spans = sum(type(shape).SPANS for shape in self.rows[first_leaf:])
        row = np.zeros(SHAPE_WIDTH)
        row[[PROGRAM, LENGTH, LEAF_COUNT, SPANS, CHILDREN, SCRATCH]] = (
            start, len(self.program) - start, leaves, spans, children, scratch(leaves, spans, children))
        box = csg.bounds()
        if box is not None:
            lo, hi = padded(*box)
            row[BOUNDED], row[LO:LO + 3], row[HI:HI + 3] = 1, lo, hi
        return row

    def _emit(self, csg: CSG, path: tuple, transforms: list) -> int:
        """The postfix program of csg at `path` ((transform, flip) per csg child above it); its
        largest number of children."""
        widest = len(csg.children)
        for c, child in enumerate(csg.children):
            x = -1
            if child.transform is not None:
                transforms.append(child.transform.packed)
                x = len(transforms) - 1
            here = path + ((x, -1 if csg.op == "difference" and c > 0 else 1),)
            if isinstance(child.shape, CSG):
                widest = max(widest, self._emit(child.shape, here, transforms))
                continue
            self.program.append((LEAF, len(self.leaves)))
            self.leaves.append((KINDS[type(child.shape)], self.first_row + len(self.rows), child.material, here))
            self.rows.append(child.shape)
        self.program.append((OPS.index(csg.op), len(csg.children)))
        return widest

    def arrays(self):
        depth = max((len(path) for *_, path in self.leaves), default=0)
        leaves = np.zeros((len(self.leaves), PATH + 2 * depth), dtype=np.int64)
        for j, (kind, row, material, path) in enumerate(self.leaves):
            leaves[j, :PATH] = kind, row, len(path), material
            leaves[j, PATH:PATH + 2 * len(path)] = np.ravel(path)
        return np.array(self.program, dtype=np.int64).reshape(-1, 2), leaves


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


def geometry(scene, tree: bool, bvh: tuple | None = None, levels=None) -> tuple[Geometry, int]:
    """The scene's geometry, and the traversal stack it needs (the scene's tree, then a mesh's).
    Without `tree` every object is listed, in file order; `bvh`: object_tree's, if made already;
    `levels`: the compiled tree build (core/bvh_build.py; the same tree as numpy's, sooner)."""
    n = len(scene.objects)
    objects, ints = np.zeros((n, SHAPE_WIDTH)), np.zeros((n, 4), dtype=np.int64)
    bounded = scene.boxes.bounded
    listed = np.flatnonzero(~bounded | (not tree))
    members, scene_bvh = (bvh or object_tree(scene, levels)) if tree else (np.zeros(0, np.int64), BVH(np.zeros((0, 3)),
                                                                                             np.zeros((0, 3))))
    trees, mesh_depth, transforms, csgs, csg_scratch = _Trees(), 0, [], _CSGs(n), 0
    trees.add(scene_bvh, members)                    # root 0
    pool, n_pool = [np.zeros((0, POOL_WIDTH))], 0

    def shape_row(shape) -> np.ndarray:
        """The shape's row, its pool appended (its rows' start, a mesh's tree root written in)."""
        nonlocal mesh_depth, n_pool
        row = np.array(shape.row, dtype=float)
        if shape.FIRST_COLUMN is not None:
            row[shape.FIRST_COLUMN] = n_pool
        if shape.ROOT_COLUMN is not None:
            tree = shape.tree(levels)                       # a mesh's, by the compiled build when given
            row[shape.ROOT_COLUMN] = trees.add(tree, np.arange(len(shape.pool)) + n_pool)
            mesh_depth = max(mesh_depth, tree.depth)
        if len(row) > SHAPE_WIDTH:
            raise ValueError(f"a {type(shape).__name__} row is wider than {SHAPE_WIDTH} columns")
        if len(shape.pool):
            pool.append(shape.pool)
            n_pool += len(shape.pool)
        return row

    for start, block in sphere_blocks(scene.objects):          # spheres kept as arrays (core/objects.py)
        end = start + len(block)
        objects[start:end, :block.rows.shape[1]] = block.rows
        ints[start:end] = np.stack([np.full(len(block), KINDS[Sphere]), np.full(len(block), -1),
                                    scene.materials.shadow[block.material], block.material], axis=1)
    for k, o in singles(scene.objects):
        shape = o.shape
        if isinstance(shape, CSG):
            objects[k], kind = csgs.add(shape, transforms), CSG_KIND
            csg_scratch = max(csg_scratch, int(objects[k, SCRATCH]))
        else:
            row, kind = shape_row(shape), KINDS[type(shape)]
            objects[k, :len(row)] = row
        if o.transform is not None:
            transforms.append(o.transform)
        ints[k] = kind, len(transforms) - 1 if o.transform is not None else -1, \
            scene.materials.shadow[o.material], o.material
    if csgs.rows:
        leaf_rows = np.zeros((len(csgs.rows), SHAPE_WIDTH))
        for j, shape in enumerate(csgs.rows):
            row = shape_row(shape)
            leaf_rows[j, :len(row)] = row
        objects = np.concatenate([objects, leaf_rows])
    geo = Geometry(objects, ints, np.array(transforms).reshape(-1, PACKED), listed.astype(np.int64),
                   *trees.arrays(), np.ascontiguousarray(np.concatenate(pool)), *csgs.arrays())
    return geo, scene_bvh.depth + max(mesh_depth, csg_scratch) + 4


def mesh_geometry(mesh) -> Geometry:
    """One mesh's faces and tree (root 0) as a Geometry, for the compiled walk over its triangles."""
    none = np.zeros(0, dtype=np.int64)
    return Geometry(np.zeros((0, SHAPE_WIDTH)), np.zeros((0, 4), dtype=np.int64), np.zeros((0, PACKED)), none,
                    mesh.bvh.nodes, mesh.bvh.links, mesh.bvh.perm, np.ascontiguousarray(mesh.pool),
                    np.zeros((0, 2), dtype=np.int64), np.zeros((0, PATH), dtype=np.int64))


def looks(scene) -> Looks:
    table = scene.materials
    samples = np.array([light.samples for light in scene.lights], dtype=np.int64)
    return Looks(table.ka, table.kd, table.ks, table.shininess, table.emission, table.kr, table.kt, table.ior,
                 table.shiny.astype(np.int64), table.mirror.astype(np.int64), table.clear.astype(np.int64),
                 table.fresnel, table.filters.astype(np.int64), table.texture, table.texels, scene.light_rows,
                 samples, np.asarray(scene.ambient, float), np.asarray(scene.background, float),
                 float(scene.offset), int(scene.settings.max_depth), scene.settings.specular == "blinn",
                 float(scene.settings.medium_ior), scene.settings.total_internal_reflection == "reflect",
                 bool(table.filters.any()), scene.settings.shadow_terminator == "offset",
                 float(scene.settings.adc_bailout))


def lanes() -> np.ndarray:
    """A packet's scratch (ROWS, W), above."""
    return np.empty((ROWS, W))


def frames(max_depth: int) -> np.ndarray:
    """The integrator's scratch: a frame per depth (at least one) and one per lane, each its columns
    above and then max_depth media slots."""
    return np.empty((max(max_depth, 1) + W, MEDIA_IOR + max_depth))
