"""Debug views as data (rtcli.view): depth, normals and albedo of the primary hits, against the geometry."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

import rtcli

SCENE = """\
image: {width: 41, height: 31}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects:
  - {name: ball, sphere: {radius: 1}, material: {diffuse: [0.9, 0.2, 0.1]}}
  - name: floor
    plane: {point: [0, -1, 0], normal: [0, 1, 0]}
    material: {diffuse: 0.5, texture: {checker: {colors: [[1, 1, 1], [0, 0, 1]], size: 1}}}
"""


@pytest.fixture(scope="module")
def scene():
    return rtcli.load_scene(SCENE)


def test_depth_is_the_distance_to_the_hit(scene):
    depth = rtcli.view(scene, "depth")
    assert depth.shape == (31, 41) and depth.dtype == np.float64
    assert depth[15, 20] == pytest.approx(4.0)                     # the centre pixel's ray meets the sphere at z = 1
    assert np.isinf(depth[0, 0])                                    # the sky
    assert np.array_equal(np.isfinite(depth), rtcli.signature(scene, workers=1) != 0)


def test_normals_face_the_eye_and_are_unit(scene):
    normal = rtcli.view(scene, "normal")
    assert normal[15, 20] == pytest.approx([0, 0, 1])
    hit = np.isfinite(rtcli.view(scene, "depth"))
    assert np.allclose(np.linalg.norm(normal[hit], axis=1), 1) and not normal[~hit].any()
    assert normal[30, 0] == pytest.approx([0, 1, 0])                # the floor, near the bottom left


def test_albedo_is_the_diffuse_color_times_the_texture(scene):
    albedo = rtcli.view(scene, "albedo")
    assert albedo[15, 20] == pytest.approx([0.9, 0.2, 0.1])
    floor = albedo[30]
    assert {tuple(c) for c in floor} == {(0.5, 0.5, 0.5), (0.0, 0.0, 0.5)}


def test_views_show_as_pictures_and_ids_are_the_signature(scene):
    for kind in ("depth", "normal", "albedo", "ids"):
        picture = Image.open(io.BytesIO(rtcli.view(scene, kind)._repr_png_()))
        assert picture.size == (41, 31) and picture.mode == "RGB"
    assert np.array_equal(rtcli.view(scene, "ids", width=20), rtcli.signature(scene, width=20, workers=1))
    with pytest.raises(rtcli.RtcliError, match="the view must be one of depth, normal, albedo, ids, got 'uv'"):
        rtcli.view(scene, "uv")
