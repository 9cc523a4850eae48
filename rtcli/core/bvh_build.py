"""Building the BVH: top-down binned SAH, one tree level at a time (pbrt-v4's binned SAH).

Each node's primitives are binned by centroid on each axis, and the cut between
bins with the least N_L A_L + N_R A_R (A = half surface area) is taken; ties go to
the first axis, then the first bin. Nodes with <= leaf_size primitives become
leaves. When no bin boundary splits a node (all centroids in one bin), it is halved
by count. A split keeps the primitives' order on each side. Nodes are numbered level
by level, a node's two children side by side, and the leaves' primitives are laid
out level by level in `perm` (the layout of core/bvh.py).

Two builds make the same tree, number for number (tests/core/test_bvh.py):
- `numpy_build` (rtcli/core/bvh_build_numpy.py): all nodes of a level at once, no
  per-primitive Python loop.
- `levels`, per node and per primitive (python and compiled variants, rtcli/kernels/variants.py):
  the compiled one builds 100,000 triangles' tree in a few hundredths of a second.
`build` runs `levels` when it is given a runner of it (the compiled variant, from its machine
code file or numba: rtcli/compiled/build.py, which the engine choice, rendering/engine.py,
hands to whatever builds trees for a render), and the numpy build otherwise.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.bvh_build_numpy import numpy_build
from rtcli.kernels.variants import INF, per_ray


def build(lo, hi, leaf_size, bins, levels=None):
    """The flat node arrays (lo, hi, child, start, count), perm and the tree's depth.

    lo, hi: (m, 3) primitive boxes; the node boxes come back as (k, 3) arrays. `levels`: a
    runner of `levels` (levels_build), else the numpy build.
    """
    if levels is not None and len(lo) > leaf_size:
        return levels_build(lo, hi, leaf_size, bins, levels)
    return numpy_build(lo, hi, leaf_size, bins)


def levels_build(lo, hi, leaf_size, bins, run):
    """The tree `levels` builds, run by `run` (a variant of it: the compiled one, or
    variants.python(levels))."""
    args = levels_args(lo, hi, leaf_size, bins)
    nodes, depth = run(*args)
    n_lo, n_hi, child, start, count, perm = args[4:10]
    return n_lo[:nodes], n_hi[:nodes], child[:nodes], start[:nodes], count[:nodes], perm, int(depth)


def levels_args(lo, hi, leaf_size: int, bins: int) -> tuple:
    """The arguments of `levels` for m primitives: the boxes, the tree's arrays to fill, sized for a
    binary tree with m non-empty leaves, and the scratch."""
    m = len(lo)
    lo, hi = (np.ascontiguousarray(x, dtype=np.float64) for x in (lo, hi))
    size = max(2 * m - 1, 1)
    n_lo, n_hi = np.empty((size, 3)), np.empty((size, 3))
    child, start, count = (np.empty(size, dtype=np.int64) for _ in range(3))
    perm = np.empty(m, dtype=np.int64)
    return (lo, hi, int(leaf_size), int(bins), n_lo, n_hi, child, start, count, perm) + scratch(lo, hi, bins)


def scratch(lo, hi, bins: int) -> tuple:
    """The working arrays of `levels` for m primitives with boxes lo, hi (m, 3): the primitives of a
    level in node order (work) with their boxes (p_lo, p_hi), the same three for the next level, the
    node sizes and bounds of this level and the next, and per node the bins' counts and boxes, the
    counts and areas right of each cut and the bins' scale per axis. The caller makes them, so that
    `levels` allocates nothing (it runs as machine code without numba: rtcli/kernels/machinecode)."""
    m = len(lo)
    return (np.arange(m), lo.copy(), hi.copy(), np.empty(m, dtype=np.int64), np.empty((m, 3)), np.empty((m, 3)),
            np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64), np.empty((m, 4, 3)), np.empty((m, 4, 3)),
            np.empty((3, bins), dtype=np.int64), np.empty((3, bins, 3)), np.empty((3, bins, 3)),
            np.empty(bins, dtype=np.int64), np.empty(bins), np.empty(3))


@per_ray(entry=True)
def levels(lo, hi, leaf_size, bins, n_lo, n_hi, child, start, count, perm, work, p_lo, p_hi, work2, p_lo2, p_hi2,
           sizes, next_sizes, bounds, next_bounds, n, b_lo, b_hi, right_n, right_area, scale):
    """The tree of `numpy_build`, node by node, into n_lo, n_hi (nodes, 3), child, start,
    count (nodes,) and perm (m,); returns (nodes, depth). The other arrays are its scratch
    (`scratch` makes them).

    The same operations on the same numbers, so the same costs and the same cuts:
    centroids are (lo + hi) / 2, and minima and maxima of finite numbers are the same
    numbers in any order (min and max here; boxes are finite). Each level's primitives
    are kept in node order with their boxes (the next level's in a second pair of
    arrays, leaves left out), and a split sums up its children's boxes and centroid
    bounds as it writes them, so that each level reads its primitives twice, in order."""
    root_bounds(lo, hi, bounds)
    sizes[0], k, first, placed, depth = lo.shape[0], 1, 0, 0, 0
    while k > 0:
        depth += 1
        offset, inner, out = 0, 0, 0                    # out: where the next level's list has got to
        for i in range(k):
            node, size = first + i, sizes[i]
            end = offset + size
            for j in range(3):
                n_lo[node, j], n_hi[node, j] = bounds[i, 0, j], bounds[i, 1, j]
            if size <= leaf_size:
                child[node], start[node], count[node] = -1, placed, size
                for q in range(offset, end):
                    perm[placed] = work[q]
                    placed += 1
            else:
                child[node], start[node], count[node] = first + k + 2 * inner, 0, 0
                fill_bins(bounds, i, offset, end, bins, p_lo, p_hi, n, b_lo, b_hi, scale)
                best, axis, cut = cheapest_cut(bins, n, b_lo, b_hi, right_n, right_area)
                split(bounds, i, offset, end, best, axis, cut, bins, scale, n, 2 * inner, out, work, p_lo, p_hi,
                      work2, p_lo2, p_hi2, next_sizes, next_bounds)
                inner += 1
                out += size
            offset = end
        work, work2, p_lo, p_lo2, p_hi, p_hi2 = work2, work, p_lo2, p_lo, p_hi2, p_hi
        sizes, next_sizes, bounds, next_bounds = next_sizes, sizes, next_bounds, bounds
        first += k
        k = 2 * inner
    return first, depth


@per_ray(inline=True)
def root_bounds(lo, hi, bounds):
    """The root's box and centroid bounds into bounds[0]: lo, hi, centroids' lo, centroids' hi."""
    for j in range(3):
        bounds[0, 0, j], bounds[0, 1, j] = lo[0, j], hi[0, j]
        bounds[0, 2, j] = bounds[0, 3, j] = (lo[0, j] + hi[0, j]) / 2
    for q in range(1, lo.shape[0]):
        for j in range(3):
            bounds[0, 0, j], bounds[0, 1, j] = min(bounds[0, 0, j], lo[q, j]), max(bounds[0, 1, j], hi[q, j])
            cj = (lo[q, j] + hi[q, j]) / 2
            bounds[0, 2, j], bounds[0, 3, j] = min(bounds[0, 2, j], cj), max(bounds[0, 3, j], cj)


@per_ray(inline=True)
def fill_bins(bounds, i, offset, end, bins, p_lo, p_hi, n, b_lo, b_hi, scale):
    """The bins of node i (its primitives offset .. end - 1): each primitive's bin per axis by its
    centroid, per bin its count (n) and box (b_lo, b_hi); scale: bins per unit length, per axis."""
    for j in range(3):
        c_lo, c_hi = bounds[i, 2, j], bounds[i, 3, j]
        scale[j] = bins / (c_hi - c_lo) if c_hi > c_lo else 0.0
    for axis in range(3):
        for bin in range(bins):
            n[axis, bin] = 0
            for j in range(3):
                b_lo[axis, bin, j], b_hi[axis, bin, j] = INF, -INF
    for q in range(offset, end):
        lx, ly, lz, hx, hy, hz = p_lo[q, 0], p_lo[q, 1], p_lo[q, 2], p_hi[q, 0], p_hi[q, 1], p_hi[q, 2]
        for axis in range(3):
            bin = min(int(((p_lo[q, axis] + p_hi[q, axis]) / 2 - bounds[i, 2, axis]) * scale[axis]), bins - 1)
            n[axis, bin] += 1
            b_lo[axis, bin, 0], b_hi[axis, bin, 0] = min(b_lo[axis, bin, 0], lx), max(b_hi[axis, bin, 0], hx)
            b_lo[axis, bin, 1], b_hi[axis, bin, 1] = min(b_lo[axis, bin, 1], ly), max(b_hi[axis, bin, 1], hy)
            b_lo[axis, bin, 2], b_hi[axis, bin, 2] = min(b_lo[axis, bin, 2], lz), max(b_hi[axis, bin, 2], hz)


@per_ray(inline=True)
def cheapest_cut(bins, n, b_lo, b_hi, right_n, right_area):
    """(cost, axis, last bin on the left) of the cut of least SAH cost N_L A_L + N_R A_R, after bin
    0 .. bins - 2 on each axis; the first of least cost wins; cost inf (cut -1) when none splits."""
    best, best_axis, best_cut = INF, 0, -1
    for axis in range(3):
        rn, lx, ly, lz, hx, hy, hz = 0, INF, INF, INF, -INF, -INF, -INF
        for bin in range(bins - 1, 0, -1):      # right of a cut: bins bin .. bins - 1
            rn += n[axis, bin]
            lx, ly, lz = min(lx, b_lo[axis, bin, 0]), min(ly, b_lo[axis, bin, 1]), min(lz, b_lo[axis, bin, 2])
            hx, hy, hz = max(hx, b_hi[axis, bin, 0]), max(hy, b_hi[axis, bin, 1]), max(hz, b_hi[axis, bin, 2])
            ex, ey, ez = hx - lx, hy - ly, hz - lz
            right_n[bin], right_area[bin] = rn, ex * ey + ey * ez + ez * ex
        ln, lx, ly, lz, hx, hy, hz = 0, INF, INF, INF, -INF, -INF, -INF
        for cut in range(bins - 1):             # left of it: bins 0 .. cut
            if n[axis, cut] == 0:
                continue                        # the cost of the cut before, which comes first
            ln += n[axis, cut]
            lx, ly, lz = min(lx, b_lo[axis, cut, 0]), min(ly, b_lo[axis, cut, 1]), min(lz, b_lo[axis, cut, 2])
            hx, hy, hz = max(hx, b_hi[axis, cut, 0]), max(hy, b_hi[axis, cut, 1]), max(hz, b_hi[axis, cut, 2])
            if ln > 0 and right_n[cut + 1] > 0:
                ex, ey, ez = hx - lx, hy - ly, hz - lz
                cost = ln * (ex * ey + ey * ez + ez * ex) + right_n[cut + 1] * right_area[cut + 1]
                if cost < best:
                    best, best_axis, best_cut = cost, axis, cut
    return best, best_axis, best_cut


@per_ray(inline=True)
def split(bounds, i, offset, end, best, best_axis, best_cut, bins, scale, n, left, out, work, p_lo, p_hi,
          work2, p_lo2, p_hi2, next_sizes, next_bounds):
    """Node i's primitives into the next level's arrays from `out`, in order on each side (halved
    by count when no cut has a finite cost), as its children `left` and `left` + 1 with their sizes
    and bounds."""
    size = end - offset
    n_left = size // 2
    if best < INF:
        n_left = 0
        for bin in range(best_cut + 1):
            n_left += n[best_axis, bin]
    right = left + 1
    next_sizes[left], next_sizes[right] = n_left, size - n_left
    for side in (left, right):
        for j in range(3):
            next_bounds[side, 0, j], next_bounds[side, 2, j] = INF, INF
            next_bounds[side, 1, j], next_bounds[side, 3, j] = -INF, -INF
    to_left, to_right = out, out + n_left
    for q in range(offset, end):
        if best < INF:
            c = (p_lo[q, best_axis] + p_hi[q, best_axis]) / 2
            goes_left = min(int((c - bounds[i, 2, best_axis]) * scale[best_axis]), bins - 1) <= best_cut
        else:
            goes_left = q - offset < n_left
        if goes_left:
            to, side = to_left, left
            to_left += 1
        else:
            to, side = to_right, right
            to_right += 1
        work2[to] = work[q]
        for j in range(3):
            l, h = p_lo[q, j], p_hi[q, j]
            p_lo2[to, j], p_hi2[to, j] = l, h
            next_bounds[side, 0, j], next_bounds[side, 1, j] = min(next_bounds[side, 0, j], l), \
                max(next_bounds[side, 1, j], h)
            cj = (l + h) / 2
            next_bounds[side, 2, j], next_bounds[side, 3, j] = min(next_bounds[side, 2, j], cj), \
                max(next_bounds[side, 3, j], cj)
