"""The three camera forms of SCENE_FORMAT.md: where each pixel's ray goes.

The eye-space basis is rebuilt here from the contract (w toward look_at,
u = normalize(w x up), v = u x w) with numpy, independently of rtcli.core.camera.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import scene_from_yaml

from rtcli.core import camera as cameras
from rtcli.errors import SceneError
from rtcli.wavefront.rays import camera_rays

EYE, LOOK, UP = np.array([1.0, 2.0, 3.0]), np.array([-2.0, 0.5, -1.0]), np.array([0.2, 1.0, 0.1])


def basis(eye, look_at, up):
    w = (look_at - eye) / np.linalg.norm(look_at - eye)
    u = np.cross(w, up)
    u /= np.linalg.norm(u)
    return u, np.cross(u, w), w


def pixel_rays(cam, nc, nr):
    """Rays through every pixel centre, row-major from the top-left pixel: (j, i, 3) origins, directions."""
    j, i = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    rays = camera_rays(cam, i.ravel() + 0.5, j.ravel() + 0.5, nc, nr)
    return rays.o.T.reshape(nr, nc, 3), rays.d.T.reshape(nr, nc, 3)


def unit(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b))


# --- field of view ---
def test_fov_centre_pixel_looks_at_look_at():
    """For odd image sizes the centre pixel's ray points exactly at look_at."""
    cam = cameras.from_fov(EYE, LOOK, UP, 40.0, 5, 3)
    origin, d = pixel_rays(cam, 5, 3)
    np.testing.assert_allclose(origin, np.broadcast_to(EYE, origin.shape), rtol=0, atol=0)
    np.testing.assert_allclose(unit(d[1, 2]), unit(LOOK - EYE), atol=1e-14)


@pytest.mark.parametrize("fov, nc, nr", [(45.0, 8, 6), (90.0, 3, 7), (10.0, 1, 1)])
def test_fov_is_the_vertical_angle_and_width_follows_aspect(fov, nc, nr):
    """Top/bottom edges are fov/2 from w; left/right edges atan(nc/nr tan(fov/2)) from w."""
    cam = cameras.from_fov(EYE, LOOK, UP, fov, nc, nr)
    u, v, w = basis(EYE, LOOK, UP)
    top, bottom, left, right = (camera_rays(cam, np.array([x]), np.array([y]), nc, nr).d[:, 0]
                                for x, y in ((nc / 2, 0), (nc / 2, nr), (0, nr / 2), (nc, nr / 2)))
    half = np.radians(fov) / 2
    for d, side, expected in ((top, v, half), (bottom, -v, half),
                              (left, -u, np.arctan(nc / nr * np.tan(half))),
                              (right, u, np.arctan(nc / nr * np.tan(half)))):
        assert angle(d, w) == pytest.approx(expected, rel=1e-12)
        assert np.dot(d, side) > 0
        assert abs(np.dot(unit(d), np.cross(side, w))) < 1e-14      # in the plane of w and that side


def test_fov_world_is_right_handed():
    """Camera at +z looking at the origin, up +y: +x appears on the right, +y at the top."""
    cam = cameras.from_fov([0, 0, 5], [0, 0, 0], [0, 1, 0], 45.0, 5, 5)
    _, d = pixel_rays(cam, 5, 5)
    assert d[2, 4, 0] > 0 and d[2, 0, 0] < 0                        # right column sees +x
    assert d[0, 2, 1] > 0 and d[4, 2, 1] < 0                        # top row sees +y


def test_right_handed_through_a_signature():
    """Built from YAML: a sphere at +x shows in the right half, one at +y in the top half."""
    from rtcli.rendering.tiles import Job, render
    s = scene_from_yaml("""
image: {width: 9, height: 9}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], up: [0, 1, 0], fov: 60}
objects:
  - sphere: {center: [1.5, 0, 0], radius: 0.5}
  - sphere: {center: [0, 1.5, 0], radius: 0.5}
""")
    ids, _ = render(s, Job(9, 9, signature=True))
    assert ids[4, 6] == 1 and ids[4, 2] == 0
    assert ids[2, 4] == 2 and ids[6, 4] == 0


def test_objects_behind_the_eye_are_not_seen():
    """Hits need t > 0: a sphere behind the camera is invisible, the same sphere in front is seen."""
    from rtcli.rendering.tiles import Job, render
    text = """
image: {{width: 3, height: 3}}
camera: {{eye: [0, 0, 5], look_at: [0, 0, 0], fov: 30}}
objects:
  - sphere: {{center: [0, 0, {z}], radius: 1}}
"""
    behind, _ = render(scene_from_yaml(text.format(z=8)), Job(3, 3, signature=True))
    front, _ = render(scene_from_yaml(text.format(z=2)), Job(3, 3, signature=True))
    np.testing.assert_array_equal(behind, 0)
    np.testing.assert_array_equal(front, 1)


# --- window (notes 000 11.2) ---
WINDOW = dict(wl=-0.8, wr=1.2, wt=0.7, wb=-0.5)


def eye_space(p, eye, look_at, up):
    u, v, w = basis(eye, look_at, up)
    q = p - eye
    return np.stack([q @ u, q @ v, q @ w], axis=-1)


def test_window_pixels_are_on_the_notes_grid():
    """p_ij = (wl + i du, wt + j dv, f) in eye space: corners exactly on (wl, wt) and (wr, wb)."""
    nc, nr, f = 4, 3, 2.5
    cam = cameras.from_window(EYE, LOOK, UP, f, WINDOW["wl"], WINDOW["wr"], WINDOW["wt"], WINDOW["wb"], nc, nr)
    origin, d = pixel_rays(cam, nc, nr)
    np.testing.assert_array_equal(origin, np.broadcast_to(EYE, origin.shape))
    q = eye_space(EYE + d, EYE, LOOK, UP)
    du, dv = (WINDOW["wr"] - WINDOW["wl"]) / (nc - 1), (WINDOW["wb"] - WINDOW["wt"]) / (nr - 1)
    j, i = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    expected = np.stack([WINDOW["wl"] + i * du, WINDOW["wt"] + j * dv, np.full(i.shape, f)], axis=-1)
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[0, 0, :2], [WINDOW["wl"], WINDOW["wt"]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[-1, -1, :2], [WINDOW["wr"], WINDOW["wb"]], rtol=0, atol=1e-12)


def test_window_from_yaml_focal_defaults_to_1():
    """Through build: the window form, focal omitted (f = 1), same grid."""
    s = scene_from_yaml("""
image: {width: 3, height: 2}
camera: {eye: [1, 2, 3], look_at: [-2, 0.5, -1], up: [0.2, 1, 0.1],
         window: {left: -0.8, right: 1.2, top: 0.7, bottom: -0.5}}
""")
    _, d = pixel_rays(s.camera(3, 2), 3, 2)
    q = eye_space(EYE + d, EYE, LOOK, UP)
    np.testing.assert_allclose(q[0, 0], [-0.8, 0.7, 1.0], atol=1e-12)
    np.testing.assert_allclose(q[0, 1], [0.2, 0.7, 1.0], atol=1e-12)
    np.testing.assert_allclose(q[1, 2], [1.2, -0.5, 1.0], atol=1e-12)


# --- screen (notes 004) ---
def test_screen_pixel_centres():
    """Pixel (i, j) is sampled at lower_left + (i+0.5)/nc h + (1 - (j+0.5)/nr) v."""
    s = scene_from_yaml("""
image: {width: 4, height: 3}
camera: {eye: [0.5, 0.25, 3], screen: {lower_left: [-2, -1, -1], horizontal: [4, 0, 0.5], vertical: [0, 2, 0.25]}}
""")
    nc, nr = 4, 3
    origin, d = pixel_rays(s.camera(nc, nr), nc, nr)
    eye = np.array([0.5, 0.25, 3])
    np.testing.assert_array_equal(origin, np.broadcast_to(eye, origin.shape))
    j, i = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    ll, h, v = np.array([-2.0, -1, -1]), np.array([4.0, 0, 0.5]), np.array([0.0, 2, 0.25])
    p = ll + ((i + 0.5) / nc)[..., None] * h + (1 - (j + 0.5) / nr)[..., None] * v
    np.testing.assert_allclose(eye + d, p, rtol=0, atol=1e-14)


# --- errors through build ---
def test_up_parallel_to_view_is_a_located_scene_error(tmp_path):
    """up along w is rejected at the `up` value, with file:line:col."""
    with pytest.raises(SceneError) as e:
        scene_from_yaml("""
image: {width: 1, height: 1}
camera: {eye: [0, 5, 0], look_at: [0, 0, 0], up: [0, 2, 0], fov: 30}
""", tmp_path)
    where = f"{tmp_path / 'scene.yaml'}:3:50"
    assert str(e.value) == f"{where}: camera.up: must not be parallel to the view direction (look_at - eye)"


def test_look_at_equal_to_eye_is_a_located_scene_error():
    """eye == look_at has no view direction: a SceneError at look_at."""
    with pytest.raises(SceneError) as e:
        scene_from_yaml("""
image: {width: 1, height: 1}
camera: {eye: [1, 1, 1], look_at: [1, 1, 1], fov: 30}
""")
    assert str(e.value) == "scene.yaml:3:35: camera.look_at: must differ from eye"
