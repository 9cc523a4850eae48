"""Debug views (rtcli.view, rtcli render --view): depth, normals, uv, albedo and bounces of each
pixel's ray, against the geometry."""

from __future__ import annotations

import io

import numpy as np
import pytest
from helpers import same_image
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


def test_normals_are_unit_and_outward(scene):
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
    for kind in ("depth", "normal", "uv", "albedo", "bounces", "ids"):
        picture = Image.open(io.BytesIO(rtcli.view(scene, kind)._repr_png_()))
        assert picture.size == (41, 31) and picture.mode == "RGB"
    assert np.array_equal(rtcli.view(scene, "ids", width=20), rtcli.signature(scene, width=20, workers=1))
    with pytest.raises(rtcli.RtcliError, match="the view must be one of normal, depth, uv, albedo, bounces, ids, "
                                               "got 'texture'"):
        rtcli.view(scene, "texture")


def test_a_face_seen_from_behind_shows_its_outward_normal():
    # The triangle's vertices turn clockwise as seen from the eye: its normal points away (-z).
    back = rtcli.load_scene("""
        image: {width: 21, height: 21}
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
        objects:
          - {triangle: {vertices: [[-1, -1, 0], [0, 1, 0], [1, -1, 0]]}}
        """)
    normal = rtcli.view(back, "normal")
    assert normal[10, 10] == pytest.approx([0, 0, -1])
    assert tuple(normal.picture[10, 10]) == (128, 128, 0)          # (n + 1) / 2: a front face would be blue


def test_uv_of_a_sphere_and_of_a_square():
    sphere = rtcli.view(SCENE, "uv")
    assert sphere[15, 20] == pytest.approx([0.5, 0.5])             # the point facing +z: longitude 0, latitude 0
    assert np.isnan(sphere[0, 0]).all()                             # the sky
    square = rtcli.view("""
        image: {width: 21, height: 21}
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 10}
        objects: [{square: {}}]
        """, "uv")
    assert square[10, 10] == pytest.approx([0.5, 0.5])             # (x + 1) / 2, (y + 1) / 2 at the origin
    u, v = square[..., 0], square[..., 1]
    assert (np.diff(u, axis=1) > 0).all() and (np.diff(v, axis=0) < 0).all()     # u grows to the right, v upward


MIRRORS = """
image: {width: 31, height: 21}
camera: {eye: [0, 0, 6], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
render: {max_depth: 4}
objects:
  - {name: mirror, sphere: {center: [-1.2, 0, 0], radius: 1}, material: {reflection: 0.8}}
  - {name: chalk, sphere: {center: [1.2, 0, 0], radius: 1}}
  - {name: wall, plane: {point: [0, 0, -3], normal: [0, 0, 1]}, material: {reflection: 0.9}}
"""


def test_bounces_count_the_deepest_ray_of_each_pixel():
    bounces = rtcli.view(MIRRORS, "bounces")
    assert bounces.dtype == np.int16 and bounces.shape == (21, 31)
    assert bounces[10, 22] == 0                                     # chalk: no secondary ray
    assert bounces[10, 8] == 1 and bounces[0, 0] == 1               # mirrors whose rays escape behind the eye
    assert bounces[10, 5] == 2                                      # the ball's rim sees the mirror wall
    inside = rtcli.view("""
        image: {width: 9, height: 7}
        camera: {eye: [0, 0, 0], look_at: [0, 0, -1], fov: 60}
        render: {max_depth: 4}
        objects: [{sphere: {radius: 10}, material: {reflection: 0.5}}]
        """, "bounces")
    assert (inside == 3).all()                                      # inside a mirror ball: max_depth - 1 everywhere
    once = rtcli.view(rtcli.load_scene(MIRRORS, max_depth=1), "bounces")
    assert (once == 0).all()                                        # no secondary rays at all
    empty = rtcli.view("""
        image: {width: 5, height: 5}
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
        objects: [{sphere: {center: [0, 0, 100], radius: 1}}]       # behind the eye
        """, "bounces")
    assert (empty == -1).all()                                      # every primary ray misses


def test_render_view_writes_the_picture_and_prints_what_it_shows(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from rtcli.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mirrors.yaml").write_text(MIRRORS)
    result = CliRunner().invoke(main, ["render", "mirrors.yaml", "--view", "depth"])
    assert result.exit_code == 0, result.output
    depth = rtcli.view(MIRRORS, "depth")
    near, far = depth[np.isfinite(depth)].min(), depth[np.isfinite(depth)].max()
    assert f"depth: {near:.6g} (white) to {far:.6g}" in result.output
    written = np.asarray(Image.open(tmp_path / "mirrors.depth.png"))
    assert np.array_equal(written, depth.picture) and not (tmp_path / "mirrors.png").exists()
    result = CliRunner().invoke(main, ["render", "mirrors.yaml", "--view", "bounces", "-o", "b.png"])
    assert result.exit_code == 0 and "0 (dark blue) to 3 (yellow, max_depth 4)" in result.output
    assert np.array_equal(np.asarray(Image.open("b.png")), rtcli.view(MIRRORS, "bounces").picture)
    result = CliRunner().invoke(main, ["render", "mirrors.yaml", "--view", "normal", "--stats"])
    assert result.exit_code == 2 and "--stats counts the rays of a render, not of a --view" in result.output


def test_render_view_ids_writes_the_id_map_that_compare_ids_reads(tmp_path, monkeypatch):
    """`render --view ids` writes NAME.ids.png as `signature --ids` does (golden_images/NAME.ids.png's
    format), so `compare --ids` and a folder comparison read it as an id map."""
    from click.testing import CliRunner

    from rtcli.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE)
    result = CliRunner().invoke(main, ["render", "s.yaml", "--view", "ids"])
    assert result.exit_code == 0, result.output
    assert result.output == "ids: the signature's ids, 0 (background) to 2, as a 16-bit id map (rtcli signature " \
                            "draws them in colors)\n"
    assert CliRunner().invoke(main, ["signature", "s.yaml", "--ids", "sig.ids.png", "--workers", "1"]).exit_code == 0
    assert same_image(tmp_path / "s.ids.png", tmp_path / "sig.ids.png")
    assert Image.open(tmp_path / "s.ids.png").mode == "I;16"
    result = CliRunner().invoke(main, ["compare", "s.ids.png", "sig.ids.png", "--ids"])
    assert result.exit_code == 0 and result.output.startswith("OK: 0 mismatched ids"), result.output
    result = CliRunner().invoke(main, ["render", "s.yaml", "--view", "ids", "-o", "s.jpg"])
    assert result.exit_code == 2 and not (tmp_path / "s.jpg").exists()
