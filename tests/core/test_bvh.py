"""BVH == brute force: the tree may only skip work, never change an answer."""

import numpy as np
import pytest

from rtcli.core import bvh as bvh_module
from rtcli.core.bvh import BVH


# --- primitives for the tests: spheres and closed axis-aligned boxes, as (ray, prim) pair tests ---
def sphere_pairs(center, radius, o, d, t_min):
    """hit_pairs for spheres: nearest root in (t_min, t_max)."""
    def hit_pairs(r, p, t_max):
        s, c = o[r] - center[p], d[r]
        a, b, k = np.sum(c * c, 1), np.sum(s * c, 1), np.sum(s * s, 1) - radius[p] ** 2
        disc = b * b - a * k
        root = np.sqrt(np.maximum(disc, 0))
        t1, t2 = (-b - root) / a, (-b + root) / a
        t = np.where(t1 > t_min, t1, t2)
        return np.where((disc >= 0) & (t > t_min) & (t < t_max), t, np.inf)
    return hit_pairs


def box_pairs(lo, hi, o, d, t_min):
    """hit_pairs for closed boxes: entry t, or exit t for rays starting inside (NaN = on a slab plane)."""
    with np.errstate(divide="ignore"):
        inv = 1 / d

    def hit_pairs(r, p, t_max):
        with np.errstate(invalid="ignore"):
            t1, t2 = (lo[p] - o[r]) * inv[r], (hi[p] - o[r]) * inv[r]
            t_in = np.fmax.reduce(np.minimum(t1, t2), axis=1)
            t_out = np.fmin.reduce(np.maximum(t1, t2), axis=1)
            t = np.where(t_in > t_min, t_in, t_out)
            return np.where((t_in <= t_out) & (t > t_min) & (t < t_max), t, np.inf)
    return hit_pairs


def brute_force(m, n, hit_pairs, t_max):
    """(n, m) matrix of every pair's t."""
    r, p = np.repeat(np.arange(n), m), np.tile(np.arange(m), n)
    return hit_pairs(r, p, np.repeat(np.broadcast_to(t_max, (n,)), m)).reshape(n, m)


def check_nearest(bvh, o, d, t_min, t_max, hit_pairs):
    t, prim = bvh.intersect(o.T.copy(), d.T.copy(), t_min, t_max, hit_pairs)       # rays as components
    all_t = brute_force(bvh.m, len(o), hit_pairs, t_max)
    expected = all_t.min(axis=1)
    np.testing.assert_array_equal(t, expected)
    assert np.array_equal(prim >= 0, np.isfinite(expected))
    unique = np.count_nonzero(all_t == expected[:, None], axis=1) == 1
    np.testing.assert_array_equal(prim[unique & np.isfinite(expected)],
                                  all_t.argmin(axis=1)[unique & np.isfinite(expected)])
    hit = prim >= 0
    np.testing.assert_array_equal(all_t[hit, prim[hit]], t[hit])       # prim is a primitive at t
    return t


def random_rays(rng, n, spread=1.5):
    """Origins in and around the unit cube; some direction components exactly zero."""
    o = rng.uniform(-spread, spread, (n, 3))
    d = rng.normal(size=(n, 3))
    d[rng.random((n, 3)) < 0.25] = 0.0
    d[np.all(d == 0, axis=1), 2] = -1.0
    return o, d


@pytest.fixture
def rng():
    return np.random.default_rng(7)


# --- nearest hit ---
@pytest.mark.parametrize("m", [1, 2, 5, 40, 300])
def test_spheres_equal_brute_force(rng, m):
    center, radius = rng.uniform(-1, 1, (m, 3)), rng.uniform(0.02, 0.3, m)
    bvh = BVH(center - radius[:, None], center + radius[:, None])
    o, d = random_rays(rng, 2000)
    t = check_nearest(bvh, o, d, 1e-6, np.inf, sphere_pairs(center, radius, o, d, 1e-6))
    assert np.isfinite(t).any() and not np.isfinite(t).all()


@pytest.mark.parametrize("pad", [bvh_module.PAD, 0.0])
def test_boxes_on_a_grid_with_axis_parallel_rays(rng, monkeypatch, pad):
    """Integer boxes and origins: rays start inside boxes, on their faces, and run along slab planes.

    Without padding the node boxes share the primitives' planes, so 0 x inf = NaN reaches the slab test.
    """
    monkeypatch.setattr(bvh_module, "PAD", pad)
    lo = rng.integers(-4, 4, (150, 3)).astype(float)
    hi = lo + rng.integers(0, 3, (150, 3))                      # some boxes are flat
    bvh = BVH(lo, hi, leaf_size=3)
    o = rng.integers(-10, 12, (3000, 3)) / 2                    # on planes and between them
    d = rng.integers(-1, 2, (3000, 3)).astype(float)
    d[np.all(d == 0, axis=1)] = [0.0, -0.0, 1.0]
    hit_pairs = box_pairs(lo, hi, o, d, 0.0)
    t = check_nearest(bvh, o, d, 0.0, np.inf, hit_pairs)
    inside = np.any(np.all((o[:, None] > lo) & (o[:, None] < hi), axis=2), axis=1)
    on_face = np.any(np.all((o[:, None] >= lo) & (o[:, None] <= hi), axis=2), axis=1) & ~inside
    assert inside.sum() > 100 and on_face.sum() > 100 and np.isfinite(t).mean() > 0.3


def test_t_min_and_t_max_arrays(rng):
    center, radius = rng.uniform(-1, 1, (200, 3)), rng.uniform(0.02, 0.2, 200)
    bvh = BVH(center - radius[:, None], center + radius[:, None])
    o, d = random_rays(rng, 1500)
    t_max = rng.uniform(0.1, 3, 1500)
    check_nearest(bvh, o, d, 0.5, t_max, sphere_pairs(center, radius, o, d, 0.5))


def test_many_identical_boxes_are_halved_by_count(rng):
    lo, hi = np.zeros((50, 3)), np.ones((50, 3))
    bvh = BVH(lo, hi, leaf_size=4)
    assert bvh.links[:, 2].max() <= 4
    o, d = random_rays(rng, 300, spread=2)
    check_nearest(bvh, o, d, 0.0, np.inf, box_pairs(lo, hi, o, d, 0.0))


def test_no_primitives():
    bvh = BVH(np.zeros((0, 3)), np.zeros((0, 3)))
    t, prim = bvh.intersect(np.zeros((3, 2)), np.ones((3, 2)), 0, np.inf, None)
    assert np.all(np.isinf(t)) and np.all(prim == -1)
    assert not bvh.any_hit(np.zeros((3, 2)), np.ones((3, 2)), 0, np.inf, None).any()


def test_no_rays(rng):
    bvh = BVH(np.zeros((3, 3)), np.ones((3, 3)))
    t, prim = bvh.intersect(np.zeros((3, 0)), np.zeros((3, 0)), 0, np.inf, None)
    assert t.shape == (0,) and prim.shape == (0,)


# --- any hit ---
def test_any_hit_equals_brute_force(rng):
    center, radius = rng.uniform(-1, 1, (300, 3)), rng.uniform(0.02, 0.15, 300)
    bvh = BVH(center - radius[:, None], center + radius[:, None])
    o, d = random_rays(rng, 3000)
    t_max = rng.uniform(0, 2, 3000)
    hit_pairs = sphere_pairs(center, radius, o, d, 1e-6)
    blocked = bvh.any_hit(o.T.copy(), d.T.copy(), 1e-6, t_max, hit_pairs)
    expected = np.isfinite(brute_force(300, 3000, hit_pairs, t_max).min(axis=1))
    np.testing.assert_array_equal(blocked, expected)
    assert 0.1 < blocked.mean() < 0.9


# --- structure ---
def test_tree_is_consistent(rng):
    lo = rng.uniform(-1, 1, (1000, 3))
    hi = lo + rng.uniform(0, 0.1, (1000, 3))
    bvh = BVH(lo, hi, leaf_size=4)
    np.testing.assert_array_equal(np.sort(bvh.perm), np.arange(1000))
    child, start, count = bvh.links.T
    box_lo, box_hi = bvh.nodes[:, :3], bvh.nodes[:, 3:]
    leaf = child < 0
    assert count[leaf].min() >= 1 and count[leaf].max() <= 4 and count[leaf].sum() == 1000
    for k in np.flatnonzero(~leaf):                             # children inside their parent
        for c in (child[k], child[k] + 1):
            assert np.all(box_lo[c] >= box_lo[k]) and np.all(box_hi[c] <= box_hi[k])
    for k in np.flatnonzero(leaf):                              # primitives inside their leaf
        p = bvh.perm[start[k]:start[k] + count[k]]
        assert np.all(lo[p] >= box_lo[k]) and np.all(hi[p] <= box_hi[k])
    b_lo, b_hi = bvh.bounds()
    np.testing.assert_array_equal(b_lo, lo.min(axis=0))
    np.testing.assert_array_equal(b_hi, hi.max(axis=0))


def test_sah_separates_two_clusters(rng):
    lo = np.concatenate([rng.uniform(0, 1, (64, 3)), rng.uniform(10, 11, (64, 3))])
    bvh = BVH(lo, lo + 0.01)
    left, right = bvh.links[0, 0], bvh.links[0, 0] + 1
    assert bvh.nodes[left, 3] < 2 and bvh.nodes[right, 0] > 9
