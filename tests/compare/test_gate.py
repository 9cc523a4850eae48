"""The golden gate on real renders: it catches the defects a renderer change can make, and
lets through the noise that does not matter. Uses the same code as `rtcli compare`."""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.compare.images import compare_ids, compare_images
from rtcli.rendering.tiles import Job, render

SCENE = """
image: {{width: 160, height: 120}}
camera: {{eye: {eye}, look_at: [0, 0.8, 0], fov: 40}}
background: [0.3, 0.4, 0.6]
ambient: [1, 1, 1]
lights: [{{position: [-3, 6, 4]}}]
objects:
  - {{name: floor, plane: {{normal: {floor_normal}}}, material: {{ambient: 0.2, diffuse: 0.6}}}}
  - {{name: ball, sphere: {{center: [-0.8, 0.8, 0], radius: 0.8}}, material: {{diffuse: [0.8, 0.3, 0.2], ambient: 0.1, specular: 0.5}}}}
{extra}
"""
BOX = "  - {name: block, polygon: {vertices: [[0.6, 0, 0.5], [1.6, 0, 0.5], [1.6, 1, 0.5], [0.6, 1, 0.5]]}}"


def rendered(yaml_scene, eye="[0, 2, 5]", floor_normal="[0, 1, 0]", extra=BOX, signature=False):
    scene = yaml_scene(SCENE.format(eye=eye, floor_normal=floor_normal, extra=extra))
    image, _ = render(scene, Job(160, 120, signature=signature, engine="numpy"))     # the tests patch its kernels
    return image


@pytest.fixture
def reference(yaml_scene):
    return rendered(yaml_scene)


def test_identical_render_passes(yaml_scene, reference):
    """The same scene rendered twice passes (and is bit-identical)."""
    again = rendered(yaml_scene)
    assert compare_images(again, reference).ok
    np.testing.assert_array_equal(again, reference)


def test_fails_on_a_one_pixel_shadow_band(reference):
    """A shadow one pixel wide and 40 long (a thin occluder's) fails the gate."""
    banded = reference.copy()
    banded[100, 40:80] = (banded[100, 40:80] * 0.6).astype(np.uint8)
    result = compare_images(banded, reference)
    assert not result.ok and result.largest_cluster == 40


GLASS = ("  - {name: glass, sphere: {center: [0.9, 0.6, 1.2], radius: 0.6},"
         " material: {diffuse: 0, ambient: 0, transmission: 0.9, ior: 1.5}}")


def test_fails_on_a_flipped_normal(yaml_scene, monkeypatch):
    """A sphere normal pointing inward (entering and leaving swapped in refraction) fails."""
    from rtcli.shapes.sphere import Sphere
    good = rendered(yaml_scene, extra=GLASS)
    outward = Sphere.kernels.normals
    inward = lambda s, pool, prim, x, y, z: tuple(-c for c in outward(s, pool, prim, x, y, z))
    monkeypatch.setattr(Sphere, "kernels", Sphere.kernels._replace(normals=inward))
    assert not compare_images(rendered(yaml_scene, extra=GLASS), good).ok


def test_fails_on_a_camera_shifted_by_half_a_pixel(yaml_scene, reference):
    """Moving the eye sideways by half a pixel's footprint fails."""
    half_pixel = 0.5 * 2 * 5.39 * np.tan(np.radians(20)) / 120        # at the look-at distance
    shifted = rendered(yaml_scene, eye=f"[{half_pixel}, 2, 5]")
    assert not compare_images(shifted, reference).ok


def test_fails_on_a_missing_object(yaml_scene, reference):
    """Dropping the block fails."""
    assert not compare_images(rendered(yaml_scene, extra=""), reference).ok


def test_passes_on_plus_minus_one_noise(reference):
    """+-1 level of noise over the whole image passes."""
    rng = np.random.default_rng(7)
    noisy = np.clip(reference.astype(int) + rng.integers(-1, 2, reference.shape), 0, 255).astype(np.uint8)
    assert compare_images(noisy, reference).ok


def test_ids_fail_on_swapped_object_and_pass_on_boundary_jitter(yaml_scene):
    """Id mode: one object's id replaced by another's fails; ids moved along an edge pass."""
    ids = rendered(yaml_scene, signature=True)
    swapped = np.where(ids == 2, 3, ids).astype(np.uint16)
    assert not compare_ids(swapped, ids).ok
    jitter = ids.copy()
    edge = np.argwhere((ids[:, 1:] != ids[:, :-1]) & (ids[:, 1:] == 2))[:8]   # first pixels of the ball
    jitter[edge[:, 0], edge[:, 1] + 1] = ids[edge[:, 0], edge[:, 1]]           # ball shrinks by a pixel there
    assert (jitter != ids).sum() == 8
    assert compare_ids(jitter, ids).ok
