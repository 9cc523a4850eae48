"""Compiled BVH traversal for triangle meshes and sphere sets (optional: numba).

The numpy traversal in bvh.py walks the tree one level at a time for a whole
array of rays; its Python overhead per level dominates renders of big meshes.
With numba installed (`pip install rtcli[fast]`), these kernels walk the same
BVH ray by ray, nearest child first, with an explicit stack, and stop shadow
feelers at their first blocker. Each (ray, primitive) test does the same
floating-point operations in the same order as the numpy code (Triangle's
Cramer solve, the sphere's stable quadratic), so both paths give the same t.

numba is imported, and the kernels compiled (or loaded from numba's cache), on
first use only: importing numba costs ~0.15 s that scenes without meshes or
sphere sets should not pay. Without numba, `ENABLED` is False and callers keep
to numpy; the functions still run as plain Python (the tests use that).
"""

from __future__ import annotations

import importlib.util
import math
import os

import numpy as np

ENABLED = os.environ.get("RTCLI_NUMBA", "1") != "0" and importlib.util.find_spec("numba") is not None
_compiled = False


def _slab(o, inv, lo, hi, node, t_near, t_far):
    """The ray meets node's box within [t_near, t_far] (bvh.BVH._slab, per ray)."""
    for k in range(3):
        t1 = (lo[k, node] - o[k]) * inv[k]
        t2 = (hi[k, node] - o[k]) * inv[k]
        if math.isnan(t1) or math.isnan(t2):          # the ray lies in that slab's plane
            continue
        t_near = max(t_near, t1 if t1 < t2 else t2)
        t_far = min(t_far, t2 if t1 < t2 else t1)
    return t_near <= t_far


def _triangle(o, d, a, e1, e2):
    """t of o + t d in the triangle a + alpha e1 + beta e2, or inf (planar.triangle_solve's operations)."""
    p0, p1, p2 = d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]
    det = p0 * e1[0] + p1 * e1[1] + p2 * e1[2]
    if det == 0.0:
        return np.inf
    inv = 1.0 / det
    s0, s1, s2 = o[0] - a[0], o[1] - a[1], o[2] - a[2]
    alpha = (s0 * p0 + s1 * p1 + s2 * p2) * inv
    q0, q1, q2 = s1 * e1[2] - s2 * e1[1], s2 * e1[0] - s0 * e1[2], s0 * e1[1] - s1 * e1[0]
    beta = (d[0] * q0 + d[1] * q1 + d[2] * q2) * inv
    t = (q0 * e2[0] + q1 * e2[1] + q2 * e2[2]) * inv
    if alpha >= 0.0 and beta >= 0.0 and alpha + beta <= 1.0:
        return t
    return np.inf


def _sphere(o, d, c, r2, t_min, t_max):
    """The first root in (t_min, t_max) of the sphere test (sphere.sphere_roots's operations)."""
    S0, S1, S2 = o[0] - c[0], o[1] - c[1], o[2] - c[2]
    A = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    B = S0 * d[0] + S1 * d[1] + S2 * d[2]
    C = (S0 * S0 + S1 * S1 + S2 * S2) - r2
    disc = B * B - A * C
    if disc < 0:
        return np.inf
    q = -B - math.copysign(math.sqrt(disc), B)
    t1 = q / A
    t2 = C / q if q != 0.0 else (np.nan if C == 0.0 else math.copysign(np.inf, C) * math.copysign(1.0, q))
    if math.isnan(t1) or math.isnan(t2) or (math.isinf(t1) and math.isinf(t2)):
        return np.inf
    near, far = min(t1, t2), max(t1, t2)
    t = near if near > t_min else far
    return t if t_min < t < t_max else np.inf


def _traverse(o, d, t_min, t_max, lo, hi, child, start, count, perm, depth, kind, prim_a, prim_b, prim_c,
              any_hit):
    """Nearest (or any) primitive hit per ray. kind 0: triangles (a, e1, e2); 1: spheres (c, r2, casts)."""
    n = o.shape[0]
    best, won = t_max.copy(), np.full(n, -1, np.int64)
    stack = np.empty(depth + 2, np.int64)              # depth-first, two children pushed per level
    inv = np.empty(3)
    for i in range(n):
        for k in range(3):
            inv[k] = 1.0 / d[i, k] if d[i, k] != 0.0 else math.copysign(np.inf, d[i, k])
        stack[0], top = 0, 1
        while top > 0:
            top -= 1
            node = stack[top]
            if not _slab(o[i], inv, lo, hi, node, t_min[i], best[i]):
                continue
            if child[node] >= 0:
                stack[top], stack[top + 1] = child[node] + 1, child[node]
                top += 2
                continue
            for j in range(start[node], start[node] + count[node]):
                p = perm[j]
                if kind == 0:
                    t = _triangle(o[i], d[i], prim_a[p], prim_b[p], prim_c[p])
                    t = t if t_min[i] < t < best[i] else np.inf
                elif prim_c[p, 0] > 0:
                    t = _sphere(o[i], d[i], prim_a[p], prim_b[p, 0], t_min[i], best[i])
                else:
                    t = np.inf
                if t < best[i]:
                    best[i], won[i] = t, p
            if any_hit and won[i] >= 0:
                break
    return best, won


def _compile() -> None:
    """Swap the plain functions for numba-compiled ones (cached on disk by numba)."""
    global _slab, _triangle, _sphere, _traverse, _compiled, ENABLED
    _compiled = True
    try:
        from numba import njit
    except ImportError:                                # a broken install: back to the numpy traversal
        ENABLED = False
        return
    _slab, _triangle, _sphere = (njit(cache=True)(f) for f in (_slab, _triangle, _sphere))
    _traverse = njit(cache=True)(_traverse)


def available() -> bool:
    """Whether callers should use the compiled traversal (numba is loaded on the first call)."""
    if ENABLED and not _compiled:
        _compile()
    return ENABLED


def traverse(bvh, o, d, t_min, t_max, kind, a, b, c, any_hit=False):
    """(t, prim) like BVH.intersect (prim -1 on a miss), or the blocked mask when any_hit."""
    if ENABLED and not _compiled:
        _compile()
    n = len(o)
    t_min = np.broadcast_to(np.asarray(t_min, dtype=float), (n,)).copy()
    t_max = np.broadcast_to(np.asarray(t_max, dtype=float), (n,)).copy()
    if bvh.m == 0 or n == 0:
        return (np.zeros(n, bool) if any_hit else (np.full(n, np.inf), np.full(n, -1, np.int64)))
    t, prim = _traverse(np.ascontiguousarray(o, dtype=float), np.ascontiguousarray(d, dtype=float),
                        t_min, t_max, bvh.lo, bvh.hi, bvh.child, bvh.start, bvh.count, bvh.perm,
                        bvh.depth, kind, a, b, c, any_hit)
    if any_hit:
        return prim >= 0
    return np.where(prim >= 0, t, np.inf), prim


def warm_up() -> None:
    """Load (or compile) the kernel now, so worker processes forked later inherit it."""
    if available():
        from rtcli.core.bvh import BVH
        one = np.zeros((1, 3))
        traverse(BVH(one, one + 1), one, one + 1, 0.0, np.inf, 0, one, one, one)
