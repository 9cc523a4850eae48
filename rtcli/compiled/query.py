"""Ray-scene queries of the compiled engine, one ray at a time: the nearest hit and shadow feelers.

The same questions as rtcli/wavefront/intersect.py asks for arrays of rays. The
listed objects (planes, or all objects of a scene without a BVH) are tested
one by one, the others through the scene's BVH, meshes through their own BVH (two
levels): one walk (rtcli/core/bvh.py), specialised here for scene objects and for
triangles. A tie (two objects hit at the very same t, say coplanar faces) goes to the
first listed object, as in the numpy engine; between two objects of a BVH it may go
to the other one than the numpy engine's level-by-level walk picks.

Which shape's kernel to call is decided by the object's KIND, through a chain of
tests built from the registry when this module is imported (`chain`): adding a shape
to rtcli/shapes/ adds it here too. This module compiles with numba: import it only
when numba is installed.

A CSG is a program (rtcli/compiled/pack.py): `csg_hit` runs it for one ray with a
stack of span lists in the traversal stack, each leaf's spans from its shape's `spans`
kernel (SPANS_ANY, a chain like HIT_ANY's over the registry's solids), each op's list
from rtcli/shapes/csg.py's `combine`, the algebra the numpy engine's CSG uses too.
A csg hit's prim names the leaf and its surface; `csg_normals`, `csg_uv` and
`material_of` answer from the leaf, as CSG.normals_at, uv_at and material_of do.
"""

from __future__ import annotations

import numpy as np

from rtcli.compiled.pack import (
    BOUNDED,
    CASTS,
    CHILDREN,
    CSG_KIND,
    DEPTH,
    HI,
    KIND,
    LEAF,
    LEAF_COUNT,
    LENGTH,
    LO,
    MATERIAL,
    PATH,
    PROGRAM,
    ROW,
    SPANS,
    XFORM,
)
from rtcli.core.bvh import ANY_CASTER, CHILD, COUNT, NEAREST, reciprocal, slab, walk, walk_rays
from rtcli.core.transform import OBJECT, affine, normal_to_world, ray_to_object
from rtcli.shapes import SHAPES
from rtcli.shapes.csg import combine, nearest
from rtcli.shapes.triangle import triangle_leaf
from rtcli.kernels.variants import INF, compiled, per_ray, to_int


# --- the dispatch on the shape's kind: one link per registered shape ---
@per_ray(inline=True)
def hit_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """HIT of the shape of kind KIND, else the next link's answer."""
    if kind == KIND_HERE:                                                           # noqa: F821
        return HIT(row, g.pool, ox, oy, oz, dx, dy, dz, t_min, t_max)                # noqa: F821
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)  # noqa: F821


@per_ray(inline=True)
def walk_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A shape hit through its own BVH over pool triangles (a mesh): prim is the face's index."""
    if kind == KIND_HERE:                                                           # noqa: F821
        t, face, _ = WALK_TRIANGLES(g, to_int(row[ROOT_AT]), ox, oy, oz, dx, dy, dz, t_min, t_max,  # noqa: F821
                                    shadow, stack, bottom)
        return t, face - to_int(row[FIRST_AT])                                      # noqa: F821
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)  # noqa: F821


@per_ray(inline=True)
def point_link(kind, row, pool, prim, x, y, z):
    """KERNEL (normals or uv) of the shape of kind KIND at a point, else the next link's."""
    if kind == KIND_HERE:                                                           # noqa: F821
        return KERNEL(row, pool, prim, x, y, z)                                      # noqa: F821
    return NEXT(kind, row, pool, prim, x, y, z)                                      # noqa: F821


@per_ray(inline=True)
def no_hit(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    return INF, 0


@per_ray(inline=True)
def no_normals(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0, 1.0, 0.0, 0.0, 1.0


@per_ray(inline=True)
def no_uv(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0


def chain(name: str, end, **bind):
    """The dispatcher calling each registered shape's kernel `name` by kind (then `end`, with `bind`)."""
    link = compiled(end, **bind)
    for kind, cls in reversed(list(enumerate(SHAPES.values()))):
        kernel = getattr(cls.kernels, name)
        if name == "hit" and kernel is None:
            link = compiled(walk_link, KIND_HERE=kind, NEXT=link, ROOT_AT=cls.ROOT_COLUMN,
                                FIRST_AT=cls.FIRST_COLUMN)
        elif name == "hit":
            link = compiled(hit_link, KIND_HERE=kind, HIT=kernel, NEXT=link)
        else:
            link = compiled(point_link, KIND_HERE=kind, KERNEL=kernel, NEXT=link)
    return link


@per_ray(inline=True)
def spans_link(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride):
    """SPANS of the solid of kind KIND_HERE stored in a span list from bt[at], bid[at] (each
    boundary's id: ident + stride x its surface); how many boundaries. Else the next link's answer."""
    if kind == KIND_HERE:                                                           # noqa: F821
        STORE(SPANS(row, pool, ox, oy, oz, dx, dy, dz), bt, bid, at, ident, stride)  # noqa: F821
        return BOUNDARIES                                                           # noqa: F821
    return NEXT(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride)  # noqa: F821


@per_ray(inline=True)
def no_spans(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride):
    return 0


@per_ray(inline=True)
def store_span(parts, bt, bid, at, ident, stride):
    """Span J of a spans kernel's answer (t_in, prim_in, t_out, prim_out, t_in, ...) as the list's
    boundaries 2 J and 2 J + 1, then the next spans (STORE_NEXT)."""
    bt[at + T_AT], bid[at + T_AT] = parts[T_IN], ident + stride * parts[P_IN]                # noqa: F821
    bt[at + T_AT + 1], bid[at + T_AT + 1] = parts[T_OUT], ident + stride * parts[P_OUT]      # noqa: F821
    STORE_NEXT(parts, bt, bid, at, ident, stride)                                           # noqa: F821


@per_ray(inline=True)
def stored(parts, bt, bid, at, ident, stride):
    return


def spans_chain():
    """SPANS_ANY: the `spans` kernel of each registered solid, by kind, into a span list."""
    link = compiled(no_spans)
    for kind, cls in reversed(list(enumerate(SHAPES.values()))):
        if cls.kernels.spans is None:
            continue
        store = compiled(stored)
        for j in reversed(range(cls.SPANS)):                 # one store per span: tuple indices are constants
            store = compiled(store_span, T_AT=2 * j, T_IN=4 * j, P_IN=4 * j + 1, T_OUT=4 * j + 2, P_OUT=4 * j + 3,
                             STORE_NEXT=store)
        link = compiled(spans_link, KIND_HERE=kind, SPANS=cls.kernels.spans, STORE=store, BOUNDARIES=2 * cls.SPANS,
                        NEXT=link)
    return link


# --- CSG: its program run for one ray, and its surfaces ---
@per_ray(inline=True)
def leaf_spans(g, leaf, ox, oy, oz, dx, dy, dz, bt, bid, at):
    """The spans of csg leaf `leaf` along a ray in the csg's space, stored from `at`: the ray is
    taken into the space of each csg child on the leaf's path in turn, as CSG.spans_of takes it down
    level by level. How many boundaries."""
    for level in range(g.leaves[leaf, DEPTH]):
        x = g.leaves[leaf, PATH + 2 * level]
        if x >= 0:
            ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
    return SPANS_ANY(g.leaves[leaf, KIND], g.objects[g.leaves[leaf, ROW]], g.pool, ox, oy, oz, dx, dy, dz,
                     bt, bid, at, leaf, len(g.leaves))


@per_ray
def csg_hit(g, row, ox, oy, oz, dx, dy, dz, t_min, t_max, stack, bottom):
    """(t, prim) of a csg (its row) for a ray in its object space: the first boundary of its spans
    in (t_min, t_max), inf if none (a ray that misses its box is not traced further). The program
    runs with a stack of span lists in stack[bottom:] (pack.scratch words): list j starts at
    lists[2 j] in bt (t, viewed as floats) and bid (the boundaries' ids), lists[2 j + 1] long;
    et, ed, eo, ei, counts are `combine`'s scratch."""
    if row[BOUNDED] != 0:
        t0, t1 = slab(row[LO], row[LO + 1], row[LO + 2], row[HI], row[HI + 1], row[HI + 2], ox, oy, oz,
                      reciprocal(dx), reciprocal(dy), reciprocal(dz), t_min, t_max)
        if not t0 <= t1:
            return INF, 0
    leaves, spans, children = to_int(row[LEAF_COUNT]), to_int(row[SPANS]), to_int(row[CHILDREN])
    lists = stack[bottom:bottom + 2 * leaves]
    at = bottom + 2 * leaves
    bt, bid = stack[at:at + 2 * spans].view(np.float64), stack[at + 2 * spans:at + 4 * spans]
    at += 4 * spans
    et, ed = stack[at:at + 2 * spans].view(np.float64), stack[at + 2 * spans:at + 4 * spans]
    eo, ei = stack[at + 4 * spans:at + 6 * spans], stack[at + 6 * spans:at + 8 * spans]
    counts = stack[at + 8 * spans:at + 8 * spans + children]
    top, end, first = 0, 0, to_int(row[PROGRAM])
    for i in range(first, first + to_int(row[LENGTH])):
        code, arg = g.program[i, 0], g.program[i, 1]
        if code == LEAF:
            n = leaf_spans(g, arg, ox, oy, oz, dx, dy, dz, bt, bid, end)
            lists[2 * top], lists[2 * top + 1] = end, n
            top, end = top + 1, end + n
        else:
            top = combine(code, arg, bt, bid, lists, top, et, ed, eo, ei, counts)
            end = lists[2 * top - 2] + lists[2 * top - 1]
    return nearest(bt, bid, lists[0], lists[1], t_min, t_max)


@per_ray(inline=True)
def csg_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """The end of HIT_ANY: a csg's hit, else the next link's answer."""
    if kind == CSG_KIND:
        return csg_hit(g, row, ox, oy, oz, dx, dy, dz, t_min, t_max, stack, bottom)
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)  # noqa: F821


@per_ray(inline=True)
def leaf_point(g, leaf, x, y, z):
    """A point in a csg's space taken into csg leaf `leaf`'s space, child by child on its path."""
    for level in range(g.leaves[leaf, DEPTH]):
        xf = g.leaves[leaf, PATH + 2 * level]
        if xf >= 0:
            x, y, z = affine(g.transforms[xf], OBJECT, x, y, z)
    return x, y, z


@per_ray
def csg_normals(g, prim, x, y, z):
    """The outward shading and geometric normals at a csg hit (prim: leaf and surface), the point
    in the csg's space: the leaf's, taken back child by child (A^-T), each flipped where the child
    is carved out by a difference (as CSG.normals_at)."""
    leaf, surface = prim % len(g.leaves), prim // len(g.leaves)
    qx, qy, qz = leaf_point(g, leaf, x, y, z)
    nx, ny, nz, gx, gy, gz = NORMALS_ANY(g.leaves[leaf, KIND], g.objects[g.leaves[leaf, ROW]], g.pool, surface,
                                         qx, qy, qz)
    for level in range(g.leaves[leaf, DEPTH] - 1, -1, -1):
        xf = g.leaves[leaf, PATH + 2 * level]
        if xf >= 0:
            nx, ny, nz = normal_to_world(g.transforms[xf], 0, nx, ny, nz)
            gx, gy, gz = normal_to_world(g.transforms[xf], 0, gx, gy, gz)
        flip = 1.0 * g.leaves[leaf, PATH + 2 * level + 1]
        nx, ny, nz, gx, gy, gz = flip * nx, flip * ny, flip * nz, flip * gx, flip * gy, flip * gz
    return nx, ny, nz, gx, gy, gz


@per_ray
def csg_uv(g, prim, x, y, z):
    """(u, v) at a csg hit: the leaf's, at the point in its space (as CSG.uv_at)."""
    leaf, surface = prim % len(g.leaves), prim // len(g.leaves)
    qx, qy, qz = leaf_point(g, leaf, x, y, z)
    return UV_ANY(g.leaves[leaf, KIND], g.objects[g.leaves[leaf, ROW]], g.pool, surface, qx, qy, qz)


@per_ray(inline=True)
def material_of(g, k, prim):
    """The material of a hit on object k: a csg leaf's own, else the object's."""
    if g.ints[k, KIND] == CSG_KIND:
        return g.leaves[prim % len(g.leaves), MATERIAL]
    return g.ints[k, MATERIAL]


WALK_TRIANGLES = compiled(walk, LEAF=triangle_leaf)
SPANS_ANY = spans_chain()
HIT_ANY = chain("hit", csg_link, NEXT=compiled(no_hit))
NORMALS_ANY, UV_ANY = chain("normals", no_normals), chain("uv", no_uv)


# --- objects and the scene ---
@per_ray(inline=True)
def object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """(t, prim) of scene object k for a world-space ray: the ray taken into object space
    (notes 000 11.3.4), then its shape's hit."""
    x = g.ints[k, XFORM]
    if x >= 0:
        ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
    return HIT_ANY(g.ints[k, KIND], g.objects[k], g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


@per_ray(inline=True)
def object_leaf(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A leaf entry of the scene's tree: object k (skipped by a feeler if it casts no shadow)."""
    if shadow != NEAREST and g.ints[k, CASTS] == 0:
        return INF, 0
    return object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


WALK_OBJECTS = compiled(walk, LEAF=object_leaf)


@per_ray(inline=True)
def scene_hit(g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack):
    """(t, object, prim): the nearest hit in (t_min, t_max); with `shadow` (a mode of
    core/bvh.py) among the objects that cast shadows, any (ANY_CASTER) or the nearest; object -1
    on a miss. stack: scratch for both tree levels."""
    best, obj, prim = t_max, -1, 0
    for j in range(len(g.listed)):
        k = g.listed[j]
        if shadow != NEAREST and g.ints[k, CASTS] == 0:
            continue
        t, p = object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, 0)
        if t < best:
            best, obj, prim = t, k, p
            if shadow == ANY_CASTER:
                return best, obj, prim
    if g.links[0, CHILD] < 0 and g.links[0, COUNT] == 0:          # no tree (a scene of few objects)
        return best, obj, prim
    t, k, p = WALK_OBJECTS(g, 0, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, 0)
    if k >= 0:
        return t, k, p
    return best, obj, prim


# --- for the numpy engine: the same walks over arrays of rays ---
WALK_RAYS_TRIANGLES = compiled(walk_rays, WALK=WALK_TRIANGLES)
WALK_RAYS_OBJECTS = compiled(walk_rays, WALK=WALK_OBJECTS)
