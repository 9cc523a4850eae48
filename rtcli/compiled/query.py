"""Ray-scene queries of the compiled path, one ray at a time (numba): the nearest hit and shadow feelers.

The same questions as intersect.py asks for arrays of rays: the listed objects
(planes, or all objects of a scene without an Accelerator) are tested one by
one, the others through the scene's BVH, meshes through their own BVH (two
levels). Each BVH is walked depth first, nearer child first, with an explicit
stack, pruned by the best t so far; a shadow feeler stops at its first blocker.
A tie (two objects hit at the very same t, say coplanar faces) goes to the first
listed object, as in the numpy core; between two objects of a BVH it may go to
the other one than the numpy core's level-by-level walk picks.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.compiled.pack import CASTS, INV, KIND, MESH, POLYGON, ROOT, XF
from rtcli.compiled.shapes import apply, hit, inline, jit, plane, triangle


@jit
def entry(nodes, node, o, inv, t_near, t_far):
    """Where the ray enters node's box within [t_near, t_far], inf if it does not
    (bvh.slab; a NaN from 0 x inf does not constrain)."""
    for k in range(3):
        t1 = (nodes[node, k] - o[k]) * inv[k]
        t2 = (nodes[node, 3 + k] - o[k]) * inv[k]
        if math.isnan(t1) or math.isnan(t2):
            continue
        t_near = max(t_near, min(t1, t2))
        t_far = min(t_far, max(t1, t2))
    return t_near if t_near <= t_far else np.inf


@jit
def push_children(nodes, child, o, inv, t_min, best, stack, top):
    """Push the children of a node whose boxes the ray enters before `best`, the nearer on top."""
    near, far = entry(nodes, child, o, inv, t_min, best), entry(nodes, child + 1, o, inv, t_min, best)
    first, second = child, child + 1
    if far < near:
        near, far, first, second = far, near, second, first
    if far < np.inf:
        stack[top] = second
        top += 1
    if near < np.inf:
        stack[top] = first
        top += 1
    return top


@jit
def reciprocal(dx, dy, dz):
    """1 / d per axis, +-inf for a zero component."""
    return (1.0 / dx if dx != 0 else math.copysign(np.inf, dx), 1.0 / dy if dy != 0 else math.copysign(np.inf, dy),
            1.0 / dz if dz != 0 else math.copysign(np.inf, dz))


@jit
def mesh_hit(nodes, links, perm, pool, root, ox, oy, oz, dx, dy, dz, t_min, t_max, any_hit, stack, bottom):
    """(t, triangle) nearest in (t_min, t_max) through the mesh tree at `root`, using
    stack[bottom:]; triangle -1 on a miss."""
    o, inv = (ox, oy, oz), reciprocal(dx, dy, dz)
    best, won = t_max, -1
    stack[bottom], top = root, bottom + 1
    while top > bottom:
        top -= 1
        node = stack[top]
        if entry(nodes, node, o, inv, t_min, best) == np.inf:     # best may have shrunk since the push
            continue
        child, start, count = links[node, 0], links[node, 1], links[node, 2]
        if child >= 0:
            top = push_children(nodes, child, o, inv, t_min, best, stack, top)
            continue
        for j in range(start, start + count):
            p = perm[j]
            tri = pool[p]
            t = triangle(tri[0:3], tri[3:6], tri[6:9], ox, oy, oz, dx, dy, dz)
            if t_min < t < best:
                best, won = t, p
        if any_hit and won >= 0:
            break
    return (best if won >= 0 else np.inf), won


@inline
def object_ray(row, transformed, ox, oy, oz, dx, dy, dz):
    """The ray in an object's space (notes 000 11.3.4)."""
    if transformed:
        ox, oy, oz = apply(row, INV, ox, oy, oz, 1)
        dx, dy, dz = apply(row, INV, dx, dy, dz, 0)
    return ox, oy, oz, dx, dy, dz


@jit
def polygon_hit(row, pool, first, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """Polygon.intersect: its plane, then the even-odd rule on the vertices pool[first:first + count]
    projected on the axes (i, j): crossings of the ray from the point along +i."""
    t = plane(row, ox, oy, oz, dx, dy, dz, t_min, t_max)
    if t == np.inf:
        return t
    i, j, count = int(row[6]), int(row[7]), int(row[8])
    p = (ox + t * dx, oy + t * dy, oz + t * dz)
    px, py, inside = p[i], p[j], False
    for r in range(count):
        a, b = pool[first + r], pool[first + (r + 1) % count]
        ax, ay, bx, by = a[i], a[j], b[i], b[j]
        if (ay > py) != (by > py) and px < ax + (py - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return t if inside else np.inf


@inline
def object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, any_hit, stack, bottom):
    """(t, prim) of scene object k for a world-space ray."""
    row, kind = g.objects[k], g.ints[k, KIND]
    ox, oy, oz, dx, dy, dz = object_ray(row, g.ints[k, XF], ox, oy, oz, dx, dy, dz)
    if kind == MESH:
        return mesh_hit(g.nodes, g.links, g.perm, g.pool, g.ints[k, ROOT], ox, oy, oz, dx, dy, dz, t_min, t_max,
                        any_hit, stack, bottom)
    if kind == POLYGON:
        return polygon_hit(row, g.pool, g.ints[k, ROOT], ox, oy, oz, dx, dy, dz, t_min, t_max), 0
    return hit(kind, row, ox, oy, oz, dx, dy, dz, t_min, t_max)


@inline
def scene_hit(g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack):
    """(t, object, prim): the nearest hit in (t_min, t_max), or with `shadow` any hit by a
    shadow-casting object; object -1 on a miss. stack: scratch for both tree levels."""
    best, obj, prim = t_max, -1, 0
    for j in range(len(g.listed)):
        k = g.listed[j]
        if shadow and not g.ints[k, CASTS]:
            continue
        t, p = object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, 0)
        if t < best:
            best, obj, prim = t, k, p
            if shadow:
                return best, obj, prim
    o, inv = (ox, oy, oz), reciprocal(dx, dy, dz)
    stack[0], top = 0, 1                             # the scene's tree has root 0
    while top > 0:
        top -= 1
        node = stack[top]
        if entry(g.nodes, node, o, inv, t_min, best) == np.inf:
            continue
        child, start, count = g.links[node, 0], g.links[node, 1], g.links[node, 2]
        if child >= 0:
            top = push_children(g.nodes, child, o, inv, t_min, best, stack, top)
            continue
        for j in range(start, start + count):
            k = g.perm[j]
            if shadow and not g.ints[k, CASTS]:
                continue
            t, p = object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, top)
            if t < best:
                best, obj, prim = t, k, p
                if shadow:
                    return best, obj, prim
    return best, obj, prim
