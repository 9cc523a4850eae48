"""The BVH build with numpy, all nodes of a level at once, no per-primitive Python loop: the same
tree as `levels` (rtcli/core/bvh_build.py, which says how a node is cut) number for number.

Boxes are (3, m) rows, so that each gather, reduction and scatter runs over contiguous arrays,
and a level's bins are [bin, ..., node] arrays whose running minima run over contiguous rows.
"""

from __future__ import annotations

import numpy as np


def numpy_build(lo, hi, leaf_size, bins):
    """The flat node arrays (lo, hi, child, start, count), perm and depth, as `levels` makes them."""
    lo_t, hi_t = np.ascontiguousarray(lo.T, dtype=np.float64), np.ascontiguousarray(hi.T, dtype=np.float64)
    p_lo, p_hi, c = lo_t, hi_t, (lo_t + hi_t) / 2         # boxes and centroids of `work`, as (3, a) rows
    work = np.arange(len(lo))                 # primitives of this level's nodes, node by node
    count = np.array([len(lo)])               # primitives per node of this level
    levels, perm, placed, first = [], [], 0, 0
    while len(count):
        start = np.cumsum(count) - count
        leaf = count <= leaf_size
        inner = ~leaf
        n_inner = np.count_nonzero(inner)
        leaf_start = np.zeros(len(count), dtype=np.int64)
        child = np.full(len(count), -1, dtype=np.int64)
        child[inner] = first + len(count) + 2 * np.arange(n_inner)
        levels.append((np.minimum.reduceat(p_lo, start, axis=1), np.maximum.reduceat(p_hi, start, axis=1),
                       child, leaf_start, np.where(leaf, count, 0)))
        first += len(count)
        if n_inner < len(count):
            in_leaf = np.repeat(leaf, count)
            leaf_start[leaf] = placed + np.cumsum(count[leaf]) - count[leaf]
            perm.append(work[in_leaf])
            placed += len(perm[-1])
            if n_inner == 0:
                break
            keep = ~in_leaf
            work, count, p_lo, p_hi, c = work[keep], count[inner], p_lo[:, keep], p_hi[:, keep], c[:, keep]
        dest, count = _split(count, p_lo, p_hi, c, bins)
        work, p_lo, p_hi, c = (_scatter(dest, x) for x in (work, p_lo, p_hi, c))
    n_lo, n_hi, child, start, count = (np.concatenate(x, axis=-1) for x in zip(*levels))
    return n_lo.T, n_hi.T, child, start, count, np.concatenate(perm), len(levels)


def _scatter(dest, x):
    """x with its last axis reordered: item i goes to dest[i]."""
    out = np.empty_like(x)
    out[..., dest] = x
    return out


def _split(count, p_lo, p_hi, c, bins):
    """Each node's best SAH cut: where each primitive goes (a stable partition, node by node)
    and the children's counts. p_lo, p_hi, c: (3, a) boxes and centroids, node by node."""
    k, a = len(count), c.shape[1]
    seg = np.repeat(np.arange(k), count)
    start = np.cumsum(count) - count
    c_lo, c_hi = np.minimum.reduceat(c, start, axis=1), np.maximum.reduceat(c, start, axis=1)
    with np.errstate(divide="ignore"):
        scale = np.where(c_hi > c_lo, bins / (c_hi - c_lo), 0.0)
    b = np.minimum(((c - np.repeat(c_lo, count, axis=1)) * np.repeat(scale, count, axis=1)).astype(np.int64),
                   bins - 1)                                   # (3, a) bin per axis
    axis, cut = _sah_cuts(b, seg, p_lo, p_hi, k, bins)
    here = np.arange(a)
    rank = here - np.repeat(start, count)
    cut_of = np.repeat(cut, count)
    left = np.where(cut_of >= 0, b.ravel()[np.repeat(axis * a, count) + here] <= cut_of,
                    rank < np.repeat(count // 2, count))
    lefts = np.cumsum(left)
    before = np.concatenate(([0], lefts))[start]              # lefts in the nodes before
    n_left = lefts[start + count - 1] - before
    left_rank = lefts - left - np.repeat(before, count)       # lefts before this one in its node
    dest = np.repeat(start, count) + np.where(left, left_rank, np.repeat(n_left, count) + rank - left_rank)
    return dest, np.stack([n_left, count - n_left], axis=1).ravel()


def _sah_cuts(b, seg, p_lo, p_hi, k, bins):
    """Per node, the axis and last left bin of least SAH cost; cut -1 when no bin boundary splits.

    Per axis, each primitive's (bin, node) slot gets its count and the min/max of its box;
    running sums and minima/maxima over the bins, from either end, give both sides of each cut.
    """
    slots = b * (3 * k) + (np.arange(3)[:, None] * k + seg)                  # [bin, axis * k + node]
    n = np.bincount(slots.ravel(), minlength=bins * 3 * k).reshape(bins, 3 * k)
    b_lo = np.full((bins, 3, 3 * k), np.inf)                                  # [bin, coordinate, axis * k + node]
    b_hi = np.full((bins, 3, 3 * k), -np.inf)
    flat_lo, flat_hi = b_lo.reshape(-1), b_hi.reshape(-1)
    for axis in range(3):
        slot = b[axis] * (9 * k) + (axis * k + seg)
        for j in range(3):
            np.minimum.at(flat_lo, slot + j * 3 * k, p_lo[j])
            np.maximum.at(flat_hi, slot + j * 3 * k, p_hi[j])
    n_l, n_r = _running(np.add, n), _running(np.add, n, backward=True)
    a_l = _half_area(_running(np.minimum, b_lo), _running(np.maximum, b_hi))
    a_r = _half_area(_running(np.minimum, b_lo, backward=True), _running(np.maximum, b_hi, backward=True))
    n_l, a_l, n_r, a_r = n_l[:-1], a_l[:-1], n_r[1:], a_r[1:]              # cut after bin 0 .. bins - 2
    with np.errstate(invalid="ignore"):
        cost = np.where((n_l > 0) & (n_r > 0), n_l * a_l + n_r * a_r, np.inf)
    cost = cost.reshape(bins - 1, 3, k).transpose(1, 0, 2).reshape(3 * (bins - 1), k)
    best = np.argmin(cost, axis=0)                            # axis-major, then bin: the first least cost
    ok = np.isfinite(cost[best, np.arange(k)])
    return best // (bins - 1), np.where(ok, best % (bins - 1), -1)


def _running(op, x, backward=False):
    """op accumulated over the first axis (the bins), from the first bin or from the last.

    A loop over the few bins, each step one operation on a contiguous row: numpy's
    accumulate along an axis other than the last is several times slower.
    """
    out = np.empty_like(x)
    steps = range(len(x) - 1, -1, -1) if backward else range(len(x))
    prev = None
    for i in steps:
        if prev is None:
            out[i] = x[i]
        else:
            op(out[prev], x[i], out=out[i])
        prev = i
    return out


def _half_area(lo, hi):
    """Half the surface area of boxes [..., coordinate, :]: ex ey + ey ez + ez ex (inf/NaN for empty boxes)."""
    with np.errstate(invalid="ignore"):
        e = hi - lo
        return e[:, 0] * e[:, 1] + e[:, 1] * e[:, 2] + e[:, 2] * e[:, 0]
