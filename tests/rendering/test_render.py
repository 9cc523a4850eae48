"""rtcli.rendering.tiles: block-size preview, tiles and workers, samples, signatures.

A pixel's value depends only on the pixel, so tile size and worker count never
change a byte of the image; a preview block is its top-left pixel repeated.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import scene_from_yaml

from rtcli.core.jitter import sample_positions
from rtcli.rendering.tiles import Job, render

W, H = 23, 17                       # not multiples of the block or tile sizes

SCENE = """
image: {{width: 23, height: 17}}
camera: {{eye: [0, 1.5, 6], look_at: [0, 0.5, 0], fov: 50}}
background: [0.1, 0.2, 0.4]
render: {{samples: {samples}, max_depth: 4}}
lights:
  - {{position: [4, 6, 5], color: [1, 0.9, 0.8]}}
  - {{position: [-3, 2, 4], area: {{u: [1, 0, 0], v: [0, 0, 1], samples: 2}}, color: [0.3, 0.3, 0.3]}}
materials:
  glass: {{ambient: 0, diffuse: 0.05, transmission: 0.9, ior: 1.5}}
objects:
  - {{plane: {{}}, material: {{texture: {{checker: {{colors: [[1, 1, 1], [0.2, 0.2, 0.2]], size: 2.5}}}}}}}}
  - {{sphere: {{center: [-1.2, 0.8, 0], radius: 0.8}}, material: {{diffuse: [0.8, 0.2, 0.2], specular: 0.6,
      shininess: 20, reflection: 0.3}}}}
  - {{sphere: {{center: [1, 0.6, 0.8], radius: 0.6}}, material: glass}}
"""


@pytest.fixture(scope="module")
def scene():
    return scene_from_yaml(SCENE.format(samples=1))


@pytest.fixture(scope="module")
def reference(scene):
    image, _ = render(scene, Job(W, H))
    return image


def test_render_returns_8bit_rgb(reference):
    """The image is uint8 (H, W, 3) and not trivially uniform."""
    assert reference.dtype == np.uint8 and reference.shape == (H, W, 3)
    assert len(np.unique(reference.reshape(-1, 3), axis=0)) > 20


@pytest.mark.parametrize("block", [2, 3, 5])
def test_block_preview_repeats_each_blocks_top_left_pixel(scene, reference, block):
    """With block_size B every B x B block (cut at the image's edges) equals its top-left pixel."""
    image, stats = render(scene, Job(W, H, block_size=block))
    assert image.shape == reference.shape
    for r0 in range(0, H, block):
        for c0 in range(0, W, block):
            cell = image[r0:r0 + block, c0:c0 + block]
            np.testing.assert_array_equal(cell, np.broadcast_to(reference[r0, c0], cell.shape),
                                          err_msg=f"block at row {r0}, column {c0}")
    assert stats.primary == len(range(0, H, block)) * len(range(0, W, block))


@pytest.mark.parametrize("tile, workers", [(7, 1), (16, 1), (64, 1), (7, 2), (16, 2)])
def test_tiles_and_workers_give_identical_bytes(scene, reference, tile, workers):
    """Any tile size and worker count gives the same image, byte for byte."""
    image, _ = render(scene, Job(W, H, tile=tile), workers=workers)
    assert image.dtype == np.uint8
    assert image.tobytes() == reference.tobytes()


def test_sample_positions_are_stratified_and_repeatable():
    """n x n samples: sample k of pixel (i, j) lies in its own 1/n x 1/n cell; the centre for n = 1."""
    i, j = np.array([0, 5, 22]), np.array([0, 7, 16])
    xs, ys = sample_positions(i, j, 1)
    np.testing.assert_array_equal(xs, [i + 0.5])
    np.testing.assert_array_equal(ys, [j + 0.5])
    n = 3
    xs, ys = sample_positions(i, j, n)
    assert xs.shape == (n * n, 3)
    fx, fy = np.floor((xs - i) * n).astype(int), np.floor((ys - j) * n).astype(int)
    for p in range(3):
        assert sorted(zip(fx[:, p], fy[:, p])) == [(a, b) for a in range(n) for b in range(n)]
    xs2, ys2 = sample_positions(i, j, n)
    np.testing.assert_array_equal(xs, xs2)
    np.testing.assert_array_equal(ys, ys2)


def test_samples_2_is_close_different_and_deterministic(reference):
    """2 x 2 samples change edge pixels a little, and repeat exactly, with 1 or 2 workers."""
    scene2 = scene_from_yaml(SCENE.format(samples=2))
    a, stats = render(scene2, Job(W, H))
    b, _ = render(scene_from_yaml(SCENE.format(samples=2)), Job(W, H, tile=7), workers=2)
    assert a.tobytes() == b.tobytes()
    assert stats.primary == 4 * W * H
    diff = np.abs(a.astype(int) - reference.astype(int)).max(axis=2)
    assert diff.max() > 50                                 # edges do change
    assert np.median(diff) <= 2 and diff.mean() < 15       # the rest barely


def test_a_pixel_is_the_mean_of_its_samples():
    """With samples n, a pixel's float color is the mean of the n x n rays traced at sample_positions."""
    from rtcli.rendering.tiles import render_tile
    from rtcli.stats import Stats
    from rtcli.wavefront.rays import camera_rays
    from rtcli.wavefront.trace import trace
    scene2 = scene_from_yaml(SCENE.format(samples=2))
    i, j = np.array([3, 11, 20, 7]), np.array([2, 8, 15, 12])
    colors, _ = render_tile(scene2, Job(W, H), i, j)
    xs, ys = sample_positions(i, j, 2)
    cam = scene2.camera(W, H)
    traced = [trace(scene2, camera_rays(cam, x, y, W, H), 1, Stats()).T for x, y in zip(xs, ys)]
    np.testing.assert_allclose(colors, np.mean(traced, axis=0), rtol=1e-12, atol=1e-15)


SIGNATURE = """
image: {width: 9, height: 5}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 60}
objects:
  - {sphere: {center: [-2.309, 0, 0], radius: 0.6}}
  - group:
      objects:
        - {sphere: {center: [0, 0, 0], radius: 0.6}}
        - {sphere: {center: [2.309, 0, 0], radius: 0.6}}
  - {plane: {point: [0, -1, 0]}}
"""


def test_signature_ids_follow_file_order_with_0_for_background():
    """Ids are 1, 2, 3 ... in file order, depth first through groups; 0 where nothing is hit."""
    ids, _ = render(scene_from_yaml(SIGNATURE), Job(9, 5, signature=True))
    assert ids.dtype == np.uint16 and ids.shape == (5, 9)
    assert ids[2, 2] == 1 and ids[2, 4] == 2 and ids[2, 6] == 3     # the three spheres, left to right
    np.testing.assert_array_equal(ids[4], 4)                        # the floor along the bottom row
    np.testing.assert_array_equal(ids[0], 0)                        # sky along the top row
    assert set(np.unique(ids)) == {0, 1, 2, 3, 4}


def test_signature_is_the_same_for_any_tiling():
    """Tiles and workers do not change the id map either."""
    s = scene_from_yaml(SIGNATURE)
    a, _ = render(s, Job(9, 5, signature=True))
    b, _ = render(s, Job(9, 5, signature=True, tile=2), workers=2)
    np.testing.assert_array_equal(a, b)


def test_tiles_shrink_with_samples_so_rays_per_tile_stay_bounded():
    """n x n samples per pixel: tiles n times narrower, about tile^2 rays each."""
    from rtcli.rendering.tiles import _tiles
    job = Job(256, 256, tile=128)
    assert max(len(r) * len(c) for r, c in _tiles(job, 1)) == 128 * 128
    assert max(len(r) * len(c) for r, c in _tiles(job, 4)) * 16 == 128 * 128
