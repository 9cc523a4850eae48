"""The shadow terminator (docs/scene-format.md, Shadow terminator): `render: {shadow_terminator:
offset}` moves the feelers of smooth faces to Hanika's shifted point, so a low-poly smooth sphere
shades as smoothly as one that casts no shadow; `none` (the default) keeps the notes' feelers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtcli.errors import SceneError
from rtcli.rendering.tiles import Job, render
from rtcli.scenefile.load import load_scene
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.triangle import Triangle, terminator

W, H = 96, 72


def low_poly_sphere(nu: int = 10, nv: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of radius 1: its vertices (on the sphere) and counter-clockwise faces."""
    rings = [(np.sin(np.pi * j / nv), np.cos(np.pi * j / nv)) for j in range(1, nv)]
    v = [(0.0, 1.0, 0.0)] + [(s * np.cos(2 * np.pi * i / nu), c, s * np.sin(2 * np.pi * i / nu))
                             for s, c in rings for i in range(nu)] + [(0.0, -1.0, 0.0)]
    ring = lambda j, i: 1 + j * nu + i % nu
    faces = [(0, ring(0, i + 1), ring(0, i)) for i in range(nu)]
    faces += [f for j in range(nv - 2) for i in range(nu)
              for f in ((ring(j, i), ring(j, i + 1), ring(j + 1, i + 1)), (ring(j, i), ring(j + 1, i + 1), ring(j + 1, i)))]
    faces += [(len(v) - 1, ring(nv - 2, i), ring(nv - 2, i + 1)) for i in range(nu)]
    return np.array(v), np.array(faces)


def scene_text(mode: str, shadow: str = "true") -> str:
    return f"""
        camera: {{eye: [0, 0, -4], look_at: [0, 0, 0], fov: 45}}
        background: [0.1, 0.1, 0.1]
        ambient: [1, 1, 1]
        render: {{shadow_terminator: {mode}}}
        lights: [{{position: [30, 20, 20], color: [1, 1, 1]}}]
        objects:
          - {{mesh: {{file: ball.obj, smooth: true}}, material: {{ambient: 0.05, diffuse: 0.9, shadow: {shadow}}},
              transform: [{{scale: [1.2, 1, 1]}}, {{rotate: {{axis: [0, 1, 0], degrees: 10}}}}]}}
    """


@pytest.fixture
def ball(tmp_path):
    v, f = low_poly_sphere()
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    (tmp_path / "ball.obj").write_text("\n".join(lines) + "\n")


def image(yaml_scene, mode, shadow="true", engine="numpy"):
    return render(yaml_scene(scene_text(mode, shadow)), Job(W, H, engine=engine))[0].astype(int)


def test_the_offset_removes_the_terminators_steps(yaml_scene, ball):
    """With shadows off the sphere shades smoothly (it cannot shadow itself): the reference. The
    notes' feelers darken whole triangles near the terminator; the offset's agree with the reference."""
    smooth = image(yaml_scene, "none", shadow="false")
    none, offset = image(yaml_scene, "none"), image(yaml_scene, "offset")
    assert (np.abs(none - smooth).max(axis=2) > 20).sum() > 30
    assert np.abs(offset - smooth).max() <= 2


@pytest.mark.parametrize("mode", ["none", "offset"])
def test_the_engines_agree(yaml_scene, ball, mode):
    np.testing.assert_array_equal(image(yaml_scene, mode), image(yaml_scene, mode, engine="compiled"))


def test_the_engines_agree_on_smooth_triangles(yaml_scene):
    """Smooth triangles (a tent, counter-clockwise from outside, under a grazing light, turned and
    stretched) in a group: the offset's shift taken to world space the same way in both engines,
    and it changes the picture."""
    text = """
        camera: {eye: [0, 1.5, -4], look_at: [0, 0.3, 0], fov: 45}
        ambient: [1, 1, 1]
        render: {shadow_terminator: MODE}
        lights: [{position: [20, 3, 2], color: [1, 1, 1]}]
        objects:
          - transform: [{scale: [1.3, 0.8, 1]}, {rotate: {axis: [0, 1, 0], degrees: 20}}]
            material: {ambient: 0.05, diffuse: 0.9}
            group:
              objects:
                - {triangle: {vertices: [[0, 1, 1], [0, 1, -1], [-1, 0, -1]], normals: [[0, 1, 0], [0, 1, 0], [-1, 0, 0]]}}
                - {triangle: {vertices: [[-1, 0, 1], [0, 1, 1], [-1, 0, -1]], normals: [[-1, 0, 0], [0, 1, 0], [-1, 0, 0]]}}
                - {triangle: {vertices: [[1, 0, 1], [1, 0, -1], [0, 1, -1]], normals: [[1, 0, 0], [1, 0, 0], [0, 1, 0]]}}
                - {triangle: {vertices: [[0, 1, 1], [1, 0, 1], [0, 1, -1]], normals: [[0, 1, 0], [1, 0, 0], [0, 1, 0]]}}
    """
    images = {}
    for mode in ("none", "offset"):
        scene = yaml_scene(text.replace("MODE", mode))
        images[mode] = render(scene, Job(W, H, engine="numpy"))[0]
        np.testing.assert_array_equal(images[mode], render(scene, Job(W, H, engine="compiled"))[0])
    assert np.abs(images["none"].astype(int) - images["offset"]).max() > 20


def test_the_shift_lifts_points_towards_the_smooth_surface():
    """Points on a low-poly sphere's faces (inside the unit sphere) move out. At an edge's midpoint
    (at cos(theta/2) from the centre) the two corners' tangent planes blend to c (2 - c^2): a little
    past the sphere, as Hanika's shift does."""
    v, f = low_poly_sphere()
    mesh = Mesh(v, f, smooth=True, normals=v, normal_faces=f)          # radial normals, as vn
    rng = np.random.default_rng(3)
    prim = rng.integers(0, len(f), 200)
    w = rng.dirichlet([1, 1, 1], 200)
    p = np.einsum("nk,nkc->cn", w, v[f[prim]])                       # points on the faces
    shift = np.array(terminator(mesh.row, mesh.pool, prim, *p))
    lifted = np.linalg.norm(p + shift, axis=0)
    assert np.all(lifted > np.linalg.norm(p, axis=0))              # outwards, off the flat face
    a, b = v[f[0, 1]], v[f[0, 2]]                                   # an edge's midpoint, at cos(theta/2)
    mid = (a + b) / 2
    c = np.linalg.norm(mid)
    shift = np.array(terminator(mesh.row, mesh.pool, np.array([0]), *mid[:, None]))[:, 0]
    np.testing.assert_allclose(np.linalg.norm(mid + shift), c * (2 - c * c), rtol=1e-12)   # Hanika's blend
    flat = Mesh(v, f, smooth=False)
    assert not np.any(terminator(flat.row, flat.pool, prim, *p))


def test_no_shift_where_the_point_lies_above_every_corners_plane():
    """A saddle-free concave corner (normals leaning inwards): the point is above each tangent plane."""
    tri = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0), normals=[[0.3, 0.3, 1], [-0.3, 0.1, 1], [0.1, -0.3, 1]])
    assert not np.any(terminator(tri.row, tri.pool, 0, 0.2, 0.3, 0.0))


def test_an_unknown_mode_is_an_error(yaml_scene, ball):
    with pytest.raises(SceneError, match="shadow_terminator"):
        yaml_scene(scene_text("pov"))


def test_the_documents_picture_is_the_example_rendered():
    """docs/images/shadow-terminator.png is docs/examples/terminator.yaml as written (left) and
    with shadow_terminator: offset (right)."""
    root = Path(__file__).resolve().parents[2]
    picture = np.asarray(Image.open(root / "docs" / "images" / "shadow-terminator.png").convert("RGB"))
    scene = load_scene(str(root / "docs" / "examples" / "terminator.yaml"))
    assert scene.settings.shadow_terminator == "none"
    w, h = scene.settings.width, scene.settings.height
    left = render(scene, Job(w, h, engine="numpy"))[0]
    scene.settings.shadow_terminator = "offset"
    right = render(scene, Job(w, h, engine="numpy"))[0]
    np.testing.assert_array_equal(picture[:h, :w], left)
    np.testing.assert_array_equal(picture[:h, w + 4:2 * w + 4], right)
