"""Bounding volume hierarchy over boxes: binned SAH build, traversal by whole arrays of rays.

Why: a mesh of 100k triangles (or a scene of 1k spheres) is too many primitives
to test every ray against each one. The BVH is generic: it knows only the
primitives' boxes; the caller supplies the exact (ray, primitive) test.

Build: binned SAH, in bvh_build.py.

Storage (flat arrays, node 0 is the root): lo/hi (3, k) node boxes (per axis), child (k,)
index of the left child (the right one is child + 1) or -1 for a leaf,
start/count (k,) a leaf's range in perm, perm (m,) primitive indices.

Traversal: a frontier of (ray, node) pairs, one tree level per step. All pairs
are slab-tested at once, with each ray's best t so far as the far limit; leaf
pairs become (ray, primitive) pairs for the caller's test, which lowers the
rays' best t so later levels prune; interior pairs expand to both children.
Rays are processed in chunks to bound memory.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.bvh_build import build

CHUNK = 1 << 13                         # rays traversed together
PAD = 1e-9                              # boxes grow by PAD x their largest |coordinate|, so rounding in
                                        # the slab test cannot drop a hit lying on a box face


class BVH:
    """BVH over m primitive boxes lo, hi (m, 3); see the module docstring."""

    def __init__(self, lo: np.ndarray, hi: np.ndarray, leaf_size: int = 4, bins: int = 12):
        lo, hi = (np.asarray(x, dtype=float).reshape(-1, 3) for x in (lo, hi))
        self.m = len(lo)
        if self.m == 0:
            self.box, self.depth = (np.full(3, np.inf), np.full(3, -np.inf)), 0
            return
        self.box = (lo.min(axis=0), hi.max(axis=0))
        self.lo, self.hi, self.child, self.start, self.count, self.perm, self.depth = build(lo, hi, leaf_size, bins)
        self.lo, self.hi = (np.ascontiguousarray(x.T) for x in padded(self.lo, self.hi, self.box))

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The union of the primitives' boxes (inf, -inf when there are none)."""
        return self.box[0].copy(), self.box[1].copy()

    def intersect(self, o, d, t_min, t_max, hit_pairs, sub=None):
        """Nearest primitive along each ray: (t (n,), prim (n,)), inf and -1 for a miss.

        hit_pairs(rays, prims, t_max_pairs) -> t (p,) is the exact test of
        (ray, primitive) pairs: a hit in (t_min, t_max_pairs), else inf. The
        result equals that test run on every primitive (ties: lowest t, any prim).
        With `sub` (an (n,) int array), hit_pairs returns (t, sub_pairs) instead,
        and each ray's winning sub_pairs value (say, a face of the primitive) lands in sub.
        """
        n = len(o)
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
        far = np.broadcast_to(np.asarray(t_max, dtype=float), (len(o),)).copy()

        def leaves(r, p):
            t = hit_pairs(r, p, far[r])
            far[r[np.isfinite(t)]] = np.nan            # NaN fails every later slab test

        self._traverse(o, d, t_min, far, leaves)
        return np.isnan(far)

    def _traverse(self, o, d, t_min, far, leaves):
        """Walk the (ray, node) frontier level by level; far (n,) is read live for pruning."""
        if self.m == 0 or len(o) == 0:
            return
        n, t_min = len(o), np.asarray(t_min, dtype=float)
        o, inv = columns(o, d)              # per axis, so the slab test runs on 1-D columns
        for s in range(0, n, CHUNK):
            rays = np.arange(s, min(s + CHUNK, n))
            rays = rays[self._slab(o[:, rays], inv[:, rays], 0, _at(t_min, rays), far[rays])]
            nodes = np.zeros(len(rays), dtype=np.int64)                              # the root
            while len(rays):
                leaf = self.child[nodes] < 0
                if leaf.any():
                    leaves(*self._leaf_pairs(rays[leaf], nodes[leaf]))
                rays, nodes = rays[~leaf], self.child[nodes[~leaf]]
                rays, nodes = self._children(o, inv, t_min, far, rays, nodes)

    def _children(self, o, inv, t_min, far, rays, left):
        """The (ray, child) pairs whose child box the ray meets, for both children of each pair's node."""
        o_r, inv_r, near, far_r = o[:, rays], inv[:, rays], _at(t_min, rays), far[rays]
        hit_l = self._slab(o_r, inv_r, left, near, far_r)
        hit_r = self._slab(o_r, inv_r, left + 1, near, far_r)
        return np.concatenate([rays[hit_l], rays[hit_r]]), np.concatenate([left[hit_l], left[hit_r] + 1])

    def _slab(self, o, inv, nodes, t_min, t_max):
        """Slab test of (ray, node) pairs against [t_min, t_max]; see slab()."""
        return slab(o, inv, [lo[nodes] for lo in self.lo], [hi[nodes] for hi in self.hi], t_min, t_max)

    def _leaf_pairs(self, rays, nodes):
        """(ray, primitive) pairs for every primitive of each (ray, leaf) pair."""
        count = self.count[nodes]
        r = np.repeat(rays, count)
        offset = np.arange(len(r)) - np.repeat(np.cumsum(count) - count, count)
        return r, self.perm[np.repeat(self.start[nodes], count) + offset]


def padded(lo, hi, scale_box=None):
    """lo, hi grown by PAD x the largest |coordinate| (of scale_box, default of lo and hi)."""
    ref = np.concatenate([np.ravel(x) for x in (scale_box if scale_box is not None else (lo, hi))])
    pad = PAD * max(np.abs(ref).max(), np.finfo(float).tiny)
    return lo - pad, hi + pad


def slab(o, inv, lo, hi, t_min, t_max):
    """Kay-Kajiya slab test: does each ray meet its box within [t_min, t_max]?

    o and inv (3, n): ray origins and 1 / directions by axis; lo, hi: per axis,
    arrays (n,) or numbers. A zero direction component gives +-inf, and NaN
    (0 x inf) when the origin lies on that slab's plane: the ray then runs inside
    the closed slab, so NaN must not constrain; np.minimum/maximum keep the NaN
    and np.fmax/fmin then skip it. A NaN t_max (a blocked ray) fails.
    """
    t_in, t_out = t_min, np.inf
    with np.errstate(invalid="ignore"):
        for k in range(3):
            t1 = (lo[k] - o[k]) * inv[k]
            t2 = (hi[k] - o[k]) * inv[k]
            t_in = np.fmax(t_in, np.minimum(t1, t2))
            t_out = np.fmin(t_out, np.maximum(t1, t2))
        return t_in <= np.minimum(t_out, t_max)


def columns(o, d):
    """(o, 1/d) as (3, n) arrays, the layout slab() wants."""
    with np.errstate(divide="ignore"):
        return np.ascontiguousarray(np.asarray(o, float).T), 1.0 / np.ascontiguousarray(np.asarray(d, float).T)


def _at(x, rays):
    """A per-ray array at rays, or the scalar itself."""
    return x if x.ndim == 0 else x[rays]
