"""Bounding volume hierarchy over boxes (notes 000 11.5): binned SAH build, one node layout,
two ways to walk it.

Why: a mesh of 100k triangles (or a scene of 1k spheres) is too many primitives
to test every ray against each one. The BVH knows only the primitives' boxes; the
caller supplies the exact (ray, primitive) test.

Build: binned SAH, in bvh_build.py.

Storage, node 0 the root: `nodes` (k, 6) each node's box lo (3) and hi (3); `links`
(k, 3) each node's first child (the second is child + 1; -1 for a leaf), and a
leaf's range start, count in `perm`; `perm` (m,) the primitives, leaf by leaf.

Two walks of the same tree, through the same slab test (`slab`):
- `BVH.intersect` / `BVH.any_hit`, numpy: a frontier of (ray, node) pairs, one tree
  level per step, for whole arrays of rays. Leaf pairs become (ray, primitive)
  pairs for the caller's test, which lowers the rays' best t so later levels prune.
- `walk`, per ray (compiled by numba in the compiled engine, and used by the numpy
  engine for meshes and sets of objects when numba is installed): depth first,
  nearer child first (entered without testing its box again), with an explicit stack,
  pruned by the best t so far. It calls
  LEAF(g, entry, ray, t_min, best, shadow, stack, top) on each leaf entry; `walk` is
  specialised for triangles or scene objects by binding LEAF (variants.compiled).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rtcli.core.bvh_build import build
from rtcli.kernels.variants import INF, kernel, narrow, per_ray

CHUNK = 1 << 13                         # rays traversed together by the numpy walk
PAD = 1e-9                              # boxes grow by PAD x their largest |coordinate|, so rounding in
                                        # the slab test cannot drop a hit lying on a box face
CHILD, START, COUNT = 0, 1, 2           # columns of links
NEAREST, ANY_CASTER, NEAREST_CASTER = 0, 1, 2     # what a per-ray walk looks for (its `shadow` mode):
                                        # the nearest hit; any object that casts shadows (a feeler
                                        # stops at the first); the nearest such object


class BVH:
    """BVH over m primitive boxes lo, hi (m, 3); see the module docstring."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray, leaf_size: int = 4, bins: int = 12, levels=None):
        lo, hi = (np.asarray(x, dtype=float).reshape(-1, 3) for x in (lo, hi))
        self.m = len(lo)
        if self.m == 0:                 # an empty tree: one leaf holding nothing
            self.box, self.depth = (np.full(3, np.inf), np.full(3, -np.inf)), 1
            self.nodes, self.links = np.zeros((1, 6)), np.array([[-1, 0, 0]], dtype=np.int64)
            self.perm = np.zeros(0, dtype=np.int64)
            return
        self.box = (lo.min(axis=0), hi.max(axis=0))
        n_lo, n_hi, child, start, count, self.perm, self.depth = build(lo, hi, leaf_size, bins, levels)
        n_lo, n_hi = padded(n_lo, n_hi, self.box)
        self.nodes = np.ascontiguousarray(np.concatenate([n_lo, n_hi], axis=1))
        self.links = np.ascontiguousarray(np.stack([child, start, count], axis=1), dtype=np.int64)

    @functools.cached_property
    def _columns(self) -> np.ndarray:
        """The node boxes as (6, nodes) rows (lo x, y, z, hi x, y, z), for the numpy walk's gathers."""
        return np.ascontiguousarray(self.nodes.T)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The union of the primitives' boxes (inf, -inf when there are none)."""
        return self.box[0].copy(), self.box[1].copy()

    # --- the numpy walk ---
    def intersect(self, o, d, t_min, t_max, hit_pairs, sub=None):
        """Nearest primitive along each ray (o, d (3, n)): (t (n,), prim (n,)), inf and -1 for a miss.

        hit_pairs(rays, prims, t_max_pairs) -> t (p,) is the exact test of
        (ray, primitive) pairs: a hit in (t_min, t_max_pairs), else inf. The
        result equals that test run on every primitive (ties: lowest t, any prim).
        With `sub` (an (n,) int array), hit_pairs returns (t, sub_pairs) instead,
        and each ray's winning sub_pairs value (say, a face of the primitive) lands in sub.
        """
        n = o.shape[1]
        best = np.broadcast_to(np.asarray(t_max, dtype=float), (n,)).copy()
        prim = np.full(n, -1, dtype=np.int64)

        def leaves(r, p):
            t, s = hit_pairs(r, p, best[r]) if sub is not None else (hit_pairs(r, p, best[r]), None)
            hit = t < best[r]
            r, p, t = r[hit], p[hit], t[hit]
            np.minimum.at(best, r, t)                  # each ray's nearest among these pairs
            won = t == best[r]
            prim[r[won]] = p[won]
            if sub is not None:
                sub[r[won]] = s[hit][won]

        self._traverse(o, d, t_min, best, leaves)
        return np.where(prim >= 0, best, np.inf), prim

    def any_hit(self, o, d, t_min, t_max, hit_pairs) -> np.ndarray:
        """(n,) bool: some primitive is hit in (t_min, t_max) (shadow feelers); blocked rays stop."""
        n = o.shape[1]
        far = np.broadcast_to(np.asarray(t_max, dtype=float), (n,)).copy()
        blocked = np.zeros(n, dtype=bool)

        def leaves(r, p):
            hit = np.isfinite(hit_pairs(r, p, far[r]))
            blocked[r[hit]] = True
            far[r[hit]] = -np.inf                      # fails every later slab test

        self._traverse(o, d, t_min, far, leaves)
        return blocked

    def _traverse(self, o, d, t_min, far, leaves):
        """Walk the (ray, node) frontier level by level; far (n,) is read live for pruning."""
        if self.m == 0 or o.shape[1] == 0:
            return
        n, t_min = o.shape[1], np.asarray(t_min, dtype=float)
        with np.errstate(divide="ignore"):
            rows = np.concatenate([o, 1.0 / d] + ([t_min[None]] if t_min.ndim else []))   # gathered as one
        for s in range(0, n, CHUNK):
            rays = np.arange(s, min(s + CHUNK, n))
            rays = rays[self._meets(np.zeros(len(rays), np.int64), *self._gather(rows, rays, t_min, far))]
            nodes = np.zeros(len(rays), dtype=np.int64)                              # the root
            while len(rays):
                child = self.links[nodes, CHILD]
                leaf = child < 0
                if leaf.any():
                    leaves(*self._leaf_pairs(rays[leaf], nodes[leaf]))
                rays, left = rays[~leaf], child[~leaf]
                ray = self._gather(rows, rays, t_min, far)             # once for both children
                hit_l, hit_r = self._meets(left, *ray), self._meets(left + 1, *ray)
                rays, nodes = np.concatenate([rays[hit_l], rays[hit_r]]), np.concatenate([left[hit_l], left[hit_r] + 1])

    @staticmethod
    def _gather(rows, rays, t_min, far):
        """The rays' origins, inverse directions, near and far limits (far read live)."""
        got = np.take(rows, rays, axis=1)
        return got[:6], t_min if t_min.ndim == 0 else got[6], far[rays]

    def _meets(self, nodes, ray, near, far):
        """Whether each ray meets its node's box within [near, far] (the rays gathered: o, 1 / d)."""
        box = np.take(self._columns, nodes, axis=1)            # (6, k): each bound contiguous
        with np.errstate(invalid="ignore"):
            t_in, t_out = slab(*box, *ray, near, far)
        return t_in <= t_out

    def _leaf_pairs(self, rays, nodes):
        """(ray, primitive) pairs for every primitive of each (ray, leaf) pair."""
        count = self.links[nodes, COUNT]
        r = np.repeat(rays, count)
        offset = np.arange(len(r)) - np.repeat(np.cumsum(count) - count, count)
        return r, self.perm[np.repeat(self.links[nodes, START], count) + offset]


def padded(lo, hi, scale_box=None):
    """lo, hi grown by PAD x the largest |coordinate| (of scale_box, default of lo and hi)."""
    ref = np.concatenate([np.ravel(x) for x in (scale_box if scale_box is not None else (lo, hi))])
    pad = PAD * max(np.abs(ref).max(), np.finfo(float).tiny)
    return lo - pad, hi + pad


@kernel
def slab(lox, loy, loz, hix, hiy, hiz, ox, oy, oz, ix, iy, iz, t_near, t_far):
    """Kay-Kajiya slab test: the part [t_near, t_far] of a ray (origin o, 1 / direction i) inside
    the box; it meets the box when t_near <= t_far. Per axis the ray is inside the slab between
    (lo - o) i and (hi - o) i. A zero direction component gives +-inf, and NaN (0 x inf) when the
    origin lies on that slab's plane: the ray then runs inside the closed slab, so the axis does
    not constrain (variants.narrow)."""
    t_near, t_far = narrow(t_near, t_far, (lox - ox) * ix, (hix - ox) * ix)
    t_near, t_far = narrow(t_near, t_far, (loy - oy) * iy, (hiy - oy) * iy)
    return narrow(t_near, t_far, (loz - oz) * iz, (hiz - oz) * iz)


@per_ray(inline=True)
def reciprocal(d):
    """1 / d, +-inf for a zero component."""
    return 1.0 / d if d != 0 else math.copysign(INF, d)


@per_ray(inline=True)
def entry(nodes, node, ox, oy, oz, ix, iy, iz, t_near, t_far):
    """Where the ray enters node's box within [t_near, t_far], inf if it does not."""
    t_in, t_out = slab(nodes[node, 0], nodes[node, 1], nodes[node, 2], nodes[node, 3], nodes[node, 4],
                       nodes[node, 5], ox, oy, oz, ix, iy, iz, t_near, t_far)
    return t_in if t_in <= t_out else INF


@per_ray
def walk(g, root, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """(t, entry, prim): the nearest hit in (t_min, t_max) among the leaf entries of the tree
    at `root` in g.nodes / g.links / g.perm, by LEAF; entry -1 on a miss. `shadow` is the mode
    (NEAREST, ANY_CASTER: the first hit found will do, NEAREST_CASTER), passed on to LEAF.
    stack[bottom:] is scratch (a LEAF may walk a tree of its own above).

    The nearer child met is popped next, untested: its box was just tested against the same
    best. The farther one is tested again when it is popped, since best may have shrunk
    meanwhile (a leaf's hit)."""
    ix, iy, iz = reciprocal(dx), reciprocal(dy), reciprocal(dz)
    best, won, prim = t_max, -1, 0
    stack[bottom], top, tested = root, bottom + 1, False      # tested: the top's box, against best as it is
    while top > bottom:
        top -= 1
        node = stack[top]
        if not tested and entry(g.nodes, node, ox, oy, oz, ix, iy, iz, t_min, best) == INF:
            continue
        tested = False
        child = g.links[node, CHILD]
        if child >= 0:                                  # push the farther child first
            near = entry(g.nodes, child, ox, oy, oz, ix, iy, iz, t_min, best)
            far = entry(g.nodes, child + 1, ox, oy, oz, ix, iy, iz, t_min, best)
            first, second = child, child + 1
            if far < near:
                near, far, first, second = far, near, second, first
            if far < INF:
                stack[top] = second
                top += 1
            if near < INF:
                stack[top] = first
                top += 1
                tested = True
            continue
        start = g.links[node, START]
        for j in range(start, start + g.links[node, COUNT]):
            t, p = LEAF(g, g.perm[j], ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, top)  # noqa: F821
            if t < best:
                best, won, prim = t, g.perm[j], p
                if shadow == ANY_CASTER:
                    return best, won, prim
    return (best if won >= 0 else INF), won, prim


@per_ray(entry=True)
def walk_rays(g, root, o, d, t_min, t_max, shadow, t, hit, prim, stack):
    """`walk` for each ray of o, d (3, n) with its t_min, t_max (n,): into t, hit (the entry, -1
    on a miss) and prim (n,)."""
    for i in range(o.shape[1]):
        t[i], hit[i], prim[i] = WALK(g, root, o[0, i], o[1, i], o[2, i], d[0, i], d[1, i], d[2, i],  # noqa: F821
                                     t_min[i], t_max[i], shadow, stack, 0)

