"""The scene BVH returns exactly what testing every object returns."""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.rendering.tiles import Job, render
from rtcli.wavefront.accel import Accelerator
from rtcli.wavefront.intersect import find_first_hit, occluded, surface
from rtcli.wavefront.rays import Rays


def random_scene(yaml_scene, seed):
    rng = np.random.default_rng(seed)
    lines = ["camera: {eye: [0, 3, 14], look_at: [0, 0, 0]}", "lights: [{position: [4, 9, 6]}]",
             "objects:", "  - {plane: {point: [0, -3, 0]}}"]
    for k in range(40):
        x, y, z = rng.uniform(-4, 4, 3)
        kind = k % 4
        if kind == 0:
            lines.append(f"  - {{sphere: {{center: [{x}, {y}, {z}], radius: {rng.uniform(0.2, 1)}}}}}")
        elif kind == 1:
            lines.append(f"  - {{box: {{}}, transform: [{{scale: {rng.uniform(0.2, 0.7)}}}, "
                         f"{{rotate: {{axis: [1, 1, 0], degrees: {rng.uniform(0, 90)}}}}}, {{translate: [{x}, {y}, {z}]}}]}}")
        elif kind == 2:
            lines.append(f"  - {{sphere: {{}}, transform: [{{scale: [0.3, 0.8, 0.5]}}, {{translate: [{x}, {y}, {z}]}}],"
                         f" material: {{shadow: {str(bool(k % 8 == 2)).lower()}}}}}")
        else:
            lines.append(f"  - {{torus: {{major: 0.5, minor: 0.15}}, transform: [{{translate: [{x}, {y}, {z}]}}]}}")
    return yaml_scene("\n".join(lines))


@pytest.mark.parametrize("seed", [1, 2])
def test_bvh_first_hit_equals_brute_force(yaml_scene, seed):
    """Same t, object and primitive for every ray, with and without the BVH."""
    scene = random_scene(yaml_scene, seed)
    rng = np.random.default_rng(seed + 10)
    rays = Rays.from_rows(rng.normal(size=(3000, 3)) * 6, rng.normal(size=(3000, 3)))
    brute = find_first_hit(scene, rays)
    scene.accel = Accelerator(scene)
    fast = find_first_hit(scene, rays)
    assert np.isfinite(brute.t).sum() > 500
    np.testing.assert_array_equal(fast.t, brute.t)
    np.testing.assert_array_equal(fast.obj, brute.obj)
    np.testing.assert_array_equal(fast.prim, brute.prim)


def test_bvh_shadow_feelers_and_surfaces_equal_brute_force(yaml_scene):
    """Shadow feelers (honouring shadow: false) and surface records agree with brute force."""
    scene = random_scene(yaml_scene, 3)
    rng = np.random.default_rng(5)
    p, light = rng.normal(size=(3, 3000)) * 5, rng.normal(size=(3, 3000)) * 5      # components
    rays = Rays.from_rows(rng.normal(size=(2000, 3)) * 6, rng.normal(size=(2000, 3)))
    brute_blocked, hits = occluded(scene, p, light), find_first_hit(scene, rays)
    seen = np.isfinite(hits.t)
    brute_surface = surface(scene, rays[seen], hits[seen])
    scene.accel = Accelerator(scene)
    np.testing.assert_array_equal(occluded(scene, p, light), brute_blocked)
    fast_surface = surface(scene, rays[seen], hits[seen])
    np.testing.assert_allclose(fast_surface.n, brute_surface.n, atol=1e-12)
    np.testing.assert_array_equal(fast_surface.material, brute_surface.material)


def test_bvh_render_is_identical(yaml_scene):
    """A whole render is byte-identical with and without the BVH."""
    scene = random_scene(yaml_scene, 4)
    brute, _ = render(scene, Job(64, 48, bvh=False, engine="numpy"))
    assert scene.accel is None
    fast, _ = render(scene, Job(64, 48, engine="numpy"))
    assert scene.accel is not None
    np.testing.assert_array_equal(fast, brute)


def test_box_culling_keeps_edge_hits_of_flat_shapes(yaml_scene):
    """Rays aimed at a rotated square's edges hit it exactly as the shape's own test says."""
    from rtcli.wavefront.intersect import object_hit
    scene = yaml_scene("""
        camera: {eye: [0, 5, 0], look_at: [0, 0, 0], up: [0, 0, 1]}
        objects:
          - {square: {}, transform: [{rotate: {axis: [1, 0, 0], degrees: 90}}, {scale: 3}, {translate: [0.1, 0.7, 0.3]}]}
    """)
    rng = np.random.default_rng(2)
    edge = rng.uniform(-3, 3, 20000)
    side = rng.integers(0, 2, 20000) * 6 - 3.0
    target = np.where(rng.integers(0, 2, 20000)[:, None] == 1, np.stack([edge, side], 1), np.stack([side, edge], 1))
    points = np.stack([target[:, 0] + 0.1, np.full(20000, 0.7), target[:, 1] + 0.3], 1)
    o = points + rng.normal(size=(20000, 3)) * [1, 0, 1] + [0, 4, 0]
    rays = Rays.from_rows(o, points - o)
    direct, _ = object_hit(scene.objects[0], rays.o, rays.d, 0.0, np.inf)
    assert np.isfinite(direct).sum() > 1000
    np.testing.assert_array_equal(find_first_hit(scene, rays).t, direct)
