"""The compiled traversal returns exactly what the numpy traversal returns.

Without numba the kernels run as plain Python, so these tests still check them,
on fewer rays.
"""

from __future__ import annotations

import numpy as np
import pytest

from rtcli import kernels
from rtcli.shapes.mesh import Mesh
from rtcli.wavefront.accel import Accelerator
from rtcli.wavefront.intersect import find_first_hit, occluded
from rtcli.wavefront.rays import Rays

N = 2000 if kernels.ENABLED else 150


@pytest.fixture
def mesh():
    rng = np.random.default_rng(11)
    v = rng.normal(size=(300, 3))
    return Mesh(v, rng.integers(0, 300, size=(400, 3)))


def rays(seed, n=N, scale=4):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d[: n // 10, 0] = 0.0                                   # zero direction components
    return rng.normal(size=(n, 3)) * scale, d


def test_triangles_nearest_hit_equals_numpy(mesh):
    """Same t and triangle for every ray, with t limits given per ray."""
    o, d = rays(1, scale=1.5)
    t_max = np.where(np.arange(len(o)) % 3 == 0, 2.0, np.inf)
    t_k, p_k = kernels.traverse(mesh.bvh, o, d, 1e-3, t_max, 0, mesh.a, mesh.e1, mesh.e2)
    t_n, p_n = mesh.bvh.intersect(o, d, 1e-3, t_max, mesh._pair_test(o, d, 1e-3))
    assert np.isfinite(t_n).sum() > len(o) // 10
    np.testing.assert_array_equal(t_k, t_n)
    np.testing.assert_array_equal(p_k, p_n)


def test_triangles_any_hit_equals_numpy(mesh):
    """Shadow feelers: blocked exactly where the numpy any-hit says."""
    o, d = rays(2)
    blocked = kernels.traverse(mesh.bvh, o, d, 0.0, 1.0, 0, mesh.a, mesh.e1, mesh.e2, any_hit=True)
    np.testing.assert_array_equal(blocked, mesh.bvh.any_hit(o, d, 0.0, 1.0, mesh._pair_test(o, d, 0.0)))
    assert 0 < blocked.sum() < len(o)


def test_sphere_set_equals_numpy(yaml_scene, monkeypatch):
    """A scene of spheres: first hits and shadow feelers agree between the two paths."""
    rng = np.random.default_rng(3)
    balls = "\n".join(f"  - {{sphere: {{center: {rng.uniform(-4, 4, 3).tolist()}, radius: {float(rng.uniform(0.2, 0.9))}}},"
                      f" material: {{shadow: {'false' if k % 5 == 0 else 'true'}}}}}" for k in range(30))
    scene = yaml_scene("camera: {eye: [0, 0, 9], look_at: [0, 0, 0]}\nobjects:\n"
                       "  - {plane: {point: [0, -5, 0]}}\n" + balls)
    scene.accel = Accelerator(scene)
    assert scene.accel.all_spheres
    o, d = rays(4, scale=6)
    monkeypatch.setattr(kernels, "ENABLED", True)
    fast, fast_blocked = find_first_hit(scene, Rays(o, d)), occluded(scene, o, o + d)
    monkeypatch.setattr(kernels, "ENABLED", False)
    slow, slow_blocked = find_first_hit(scene, Rays(o, d)), occluded(scene, o, o + d)
    np.testing.assert_array_equal(fast.t, slow.t)
    np.testing.assert_array_equal(fast.obj, slow.obj)
    np.testing.assert_array_equal(fast_blocked, slow_blocked)


def test_deep_tree_does_not_overflow_the_stack():
    """Triangles growing geometrically make a tree deeper than any fixed stack; still exact."""
    m = 500
    x = 1.5 ** np.arange(m) / 1.5 ** (m / 2)
    a = np.stack([x, 0 * x, 0 * x], 1)
    v = np.concatenate([a, a + np.stack([0.1 * x, 0 * x, 0 * x], 1), a + np.stack([0 * x, 0.1 * x, 0 * x], 1)])
    mesh = Mesh(v, np.stack([np.arange(m), np.arange(m) + m, np.arange(m) + 2 * m], 1))
    assert mesh.bvh.depth > 64
    o, d = np.array([[x[5] * 1.01, 0.01 * x[5], 1.0]]), np.array([[0, 0, -1.0]])
    t, prim = kernels.traverse(mesh.bvh, o, d, 0.0, np.inf, 0, mesh.a, mesh.e1, mesh.e2)
    assert (t[0], prim[0]) == (1.0, 5)
