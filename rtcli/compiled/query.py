"""Ray-scene queries of the compiled engine, one ray at a time: the nearest hit and shadow feelers.

The same questions as rtcli/wavefront/intersect.py asks for arrays of rays. The
listed objects (planes, or all objects of a scene without a BVH) are tested
one by one, the others through the scene's BVH, meshes through their own BVH (two
levels): one walk (rtcli/core/bvh.py), specialised here for scene objects and for
triangles. A tie (two objects hit at the very same t, say coplanar faces) goes to the
first listed object, as in the numpy engine; between two objects of a BVH it may go
to the other one than the numpy engine's level-by-level walk picks.

Which shape's kernel to call is decided by the object's KIND, through a chain of
tests built from the registry (rtcli/compiled/dispatch.py), ending in the CSG's link
(`csg_link`, its NEXT bound as the chain is made). This module compiles with numba:
import it only when numba is installed.

A CSG is a program (rtcli/compiled/pack.py): `csg_hit` runs it for one ray with a
stack of span lists in the traversal stack, each leaf's spans from its shape's `spans`
kernel (SPANS_ANY, a chain like HIT_ANY's over the registry's solids), each op's list
from rtcli/shapes/csg.py's `combine`, the algebra the numpy engine's CSG uses too.
A csg hit's prim names the leaf and its surface; `csg_normals`, `csg_uv` and
`material_of` answer from the leaf, as CSG.normals_at, uv_at and material_of do.
"""

from __future__ import annotations

import numpy as np

from rtcli.compiled.dispatch import NEXT, WALK_TRIANGLES, chain, no_hit, no_normals, no_uv, spans_chain
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
from rtcli.kernels.variants import INF, compiled, per_ray, to_int
from rtcli.shapes.csg import combine, nearest


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
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


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


@per_ray
def object_leaf_one(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """object_leaf as a call of its own, for a packet's lanes one by one (compiled/packets.py)."""
    return object_leaf(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


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


@per_ray(entry=True)
def scene_rays(g, o, d, t_min, t_max, shadow, t, hit, prim, stack):
    """scene_hit for each ray of o, d (3, n) with its t_min, t_max (n,): into t, hit (the object,
    -1 on a miss) and prim (n,); for tests, beside packets.packet_rays."""
    for i in range(o.shape[1]):
        t[i], hit[i], prim[i] = scene_hit(g, o[0, i], o[1, i], o[2, i], d[0, i], d[1, i], d[2, i], t_min[i],
                                          t_max[i], shadow, stack)


# --- for the numpy engine: the same walks over arrays of rays ---
WALK_RAYS_TRIANGLES = compiled(walk_rays, WALK=WALK_TRIANGLES)
WALK_RAYS_OBJECTS = compiled(walk_rays, WALK=WALK_OBJECTS)
