"""The BVH build as it was first written (rtcli/core/bvh_build.py before its numpy build was
reworked and its compiled build added): the reference both must match, tree for tree.

Top-down binned SAH, one tree level at a time (pbrt-v4's binned SAH).

Each node's primitives are binned by centroid on each axis, and the split between
bins with the least N_L A_L + N_R A_R (A = half surface area) is taken; nodes with
<= leaf_size primitives become leaves. When all centroids coincide, a node is
halved by count. numpy handles all nodes of a level together, so there is no
per-primitive Python loop.
"""

from __future__ import annotations

import numpy as np


def build(lo, hi, leaf_size, bins):
    """The flat node arrays (lo, hi, child, start, count), perm and the tree's depth."""
    center = (lo + hi) / 2
    work = np.arange(len(lo))                 # primitives of this level's inner nodes, node by node
    count = np.array([len(lo)])               # primitives per node of this level
    levels, perm, placed, first = [], [], 0, 0
    while len(count):
        start = np.cumsum(count) - count
        leaf = count <= leaf_size
        in_leaf = np.repeat(leaf, count)
        leaf_start = np.zeros(len(count), dtype=np.int64)
        leaf_start[leaf] = placed + np.cumsum(count[leaf]) - count[leaf]
        child = np.full(len(count), -1, dtype=np.int64)
        child[~leaf] = first + len(count) + 2 * np.arange(np.count_nonzero(~leaf))
        levels.append((np.minimum.reduceat(lo[work], start, axis=0), np.maximum.reduceat(hi[work], start, axis=0),
                       child, leaf_start, np.where(leaf, count, 0)))
        perm.append(work[in_leaf])
        placed, first = placed + np.count_nonzero(in_leaf), first + len(count)
        work, count = work[~in_leaf], count[~leaf]
        if len(count):
            work, count = _split(work, count, lo, hi, center, bins)
    columns = [np.concatenate(c) for c in zip(*levels)]
    return (*columns, np.concatenate(perm), len(levels))


def _split(work, count, lo, hi, center, bins):
    """Partition each node's primitives by its best SAH cut; returns the children's work and counts."""
    k = len(count)
    seg = np.repeat(np.arange(k), count)
    start = np.cumsum(count) - count
    c = center[work]
    c_lo, c_hi = np.minimum.reduceat(c, start, axis=0), np.maximum.reduceat(c, start, axis=0)
    with np.errstate(divide="ignore"):
        scale = np.where(c_hi > c_lo, bins / (c_hi - c_lo), 0.0)
    b = np.minimum(((c - c_lo[seg]) * scale[seg]).astype(np.int64), bins - 1)    # (a, 3) bin per axis
    axis, cut = _sah_cuts(b, seg, lo[work], hi[work], k, bins)
    rank = np.arange(len(work)) - start[seg]
    left = np.where(cut[seg] >= 0, b[np.arange(len(work)), axis[seg]] <= cut[seg], rank < count[seg] // 2)
    order = np.argsort(2 * seg + ~left, kind="stable")
    n_left = np.bincount(seg[left], minlength=k)
    return work[order], np.stack([n_left, count - n_left], axis=1).ravel()


def _sah_cuts(b, seg, p_lo, p_hi, k, bins):
    """Per node, the axis and last left bin of least SAH cost; cut -1 when no bin boundary splits."""
    key = (seg[:, None] * 3 + np.arange(3)) * bins + b                 # (a, 3): (node, axis, bin)
    size = k * 3 * bins
    n = np.bincount(key.ravel(), minlength=size).reshape(k, 3, bins)
    b_lo, b_hi = np.full((3, size), np.inf), np.full((3, size), -np.inf)
    for axis in range(3):
        for j in range(3):
            np.minimum.at(b_lo[j], key[:, axis], p_lo[:, j])
            np.maximum.at(b_hi[j], key[:, axis], p_hi[:, j])
    b_lo, b_hi = (x.reshape(3, k, 3, bins).transpose(1, 2, 3, 0) for x in (b_lo, b_hi))
    n_l, a_l = np.cumsum(n, axis=2), _half_area(np.minimum.accumulate(b_lo, axis=2),
                                                np.maximum.accumulate(b_hi, axis=2))
    n_r = np.cumsum(n[:, :, ::-1], axis=2)[:, :, ::-1]
    a_r = _half_area(np.minimum.accumulate(b_lo[:, :, ::-1], axis=2)[:, :, ::-1],
                     np.maximum.accumulate(b_hi[:, :, ::-1], axis=2)[:, :, ::-1])
    n_l, a_l, n_r, a_r = n_l[:, :, :-1], a_l[:, :, :-1], n_r[:, :, 1:], a_r[:, :, 1:]
    with np.errstate(invalid="ignore"):
        cost = np.where((n_l > 0) & (n_r > 0), n_l * a_l + n_r * a_r, np.inf).reshape(k, -1)
    best = np.argmin(cost, axis=1)
    ok = np.isfinite(cost[np.arange(k), best])
    return best // (bins - 1), np.where(ok, best % (bins - 1), -1)


def _half_area(lo, hi):
    """Half the surface area of boxes (..., 3): ex ey + ey ez + ez ex (inf/NaN for empty boxes)."""
    with np.errstate(invalid="ignore"):
        e = hi - lo
        return e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0]
