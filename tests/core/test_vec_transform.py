"""rtcli.core.vec (unit, reflect) and rtcli.core.transform (composition order, normals, singular matrices)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import scene_from_yaml

from rtcli.core import transform as tf
from rtcli.core.vec import cross3, dot3, reflect, split, stack, unit3
from rtcli.errors import SceneError

RNG = np.random.default_rng(42)


# --- vec ---
def test_normalize_gives_unit_vectors_in_the_same_direction():
    """|unit3(a)| = 1 and unit3(a) = a / |a|, for rows of any scale and for one vector."""
    a = RNG.normal(size=(100, 3)) * 10.0 ** RNG.uniform(-6, 6, (100, 1))
    u = unit3(a)
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(u * np.linalg.norm(a, axis=1)[:, None], a, rtol=1e-14)
    np.testing.assert_allclose(unit3(np.array([3.0, 0, -4])), [0.6, 0, -0.8], rtol=1e-15)


def test_dot_and_cross_are_rowwise():
    """dot and cross on (n, 3) rows agree with numpy's."""
    a, b = RNG.normal(size=(50, 3)), RNG.normal(size=(50, 3))
    np.testing.assert_allclose(dot3(a, b), np.einsum("ij,ij->i", a, b), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(cross3(a, b), np.cross(a, b), rtol=1e-13, atol=1e-15)


def test_reflect_angle_in_equals_angle_out():
    """r = d - 2(d.n)n: r.n = -(d.n), same tangential part, |r| = |d|, r in the plane of d and n."""
    n = unit3(RNG.normal(size=(200, 3)))
    d = RNG.normal(size=(200, 3))
    r = stack(*reflect(*split(d), *split(n)))
    np.testing.assert_allclose(dot3(r, n), -dot3(d, n), atol=1e-13)
    np.testing.assert_allclose(r - dot3(r, n)[:, None] * n, d - dot3(d, n)[:, None] * n, atol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), np.linalg.norm(d, axis=1), rtol=1e-13)
    np.testing.assert_allclose(dot3(r, cross3(d, n)), 0, atol=1e-13)
    np.testing.assert_allclose(reflect(1.0, -1.0, 0.0, 0.0, 1.0, 0.0), [1, 1, 0])


# --- transform ---
P = np.array([[1.0, 1.0, 1.0]])


def test_scale_then_translate_differs_from_translate_then_scale():
    """a.then(b) applies a first: scale 2 then +x gives 2p + x; +x then scale 2 gives 2(p + x)."""
    s, t = tf.scale(2.0), tf.translate([1, 0, 0])
    np.testing.assert_allclose(s.then(t).point(P), [[3, 2, 2]])
    np.testing.assert_allclose(t.then(s).point(P), [[4, 2, 2]])


def test_rotate_is_right_handed():
    """rotate(z, 90) takes +x to +y; rotate(x, 90) takes +y to +z; rotate(y, 90) takes +z to +x."""
    np.testing.assert_allclose(tf.rotate([0, 0, 1], 90).point(np.array([[1.0, 0, 0]])), [[0, 1, 0]], atol=1e-15)
    np.testing.assert_allclose(tf.rotate([1, 0, 0], 90).point(np.array([[0.0, 1, 0]])), [[0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(tf.rotate([0, 2, 0], 90).point(np.array([[0.0, 0, 1]])), [[1, 0, 0]], atol=1e-15)


def object_transform(steps: str):
    s = scene_from_yaml(f"""
camera: {{eye: [0, 0, 9], look_at: [0, 0, 0]}}
objects:
  - sphere: {{}}
    transform: {steps}
""")
    return s.objects[0].world_from_object


@pytest.mark.parametrize("steps, expected", [
    ("[{scale: 2}, {translate: [1, 0, 0]}]", [3, 2, 2]),
    ("[{translate: [1, 0, 0]}, {scale: 2}]", [4, 2, 2]),
    ("[{scale: [2, 1, 1]}, {rotate: {axis: [0, 0, 1], degrees: 90}}, {translate: [0, 0, 5]}]", [-1, 2, 6]),
    ("[{translate: [0, 0, 5]}, {rotate: {axis: [0, 0, 1], degrees: 90}}, {scale: [2, 1, 1]}]", [-2, 1, 6]),
])
def test_yaml_transform_list_applies_in_the_order_written(steps, expected):
    """The object's point (1, 1, 1) goes through the listed steps first to last."""
    np.testing.assert_allclose(object_transform(steps).point(P), [expected], atol=1e-14)


def random_affine(mirror=False):
    s = RNG.uniform(0.3, 3, 3) * np.where(np.arange(3) == 0, -1 if mirror else 1, 1)
    return tf.scale(s).then(tf.rotate(RNG.normal(size=3), RNG.uniform(0, 360))).then(
        tf.translate(RNG.normal(size=3)))


@pytest.mark.parametrize("mirror", [False, True])
def test_inverse_undoes_the_transform(mirror):
    """m_inv is the inverse: inverse.point(point(p)) = p, and vectors ignore the translation."""
    t = random_affine(mirror)
    p = RNG.normal(size=(20, 3))
    np.testing.assert_allclose(t.inverse.point(t.point(p)), p, atol=1e-12)
    np.testing.assert_allclose(t.m @ t.m_inv, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(t.vector(p), t.point(p) - t.point(np.zeros((1, 3))), atol=1e-12)


@pytest.mark.parametrize("mirror", [False, True])
def test_normals_stay_perpendicular_to_transformed_tangents(mirror):
    """A^-T n is perpendicular to A t1 and A t2 when n = t1 x t2 (notes 000 11.6.1); A n is not."""
    t = random_affine(mirror)
    t1, t2 = RNG.normal(size=(100, 3)), RNG.normal(size=(100, 3))
    n = cross3(t1, t2)
    nw = unit3(t.normal(n))
    for tangent in (t1, t2):
        np.testing.assert_allclose(dot3(nw, unit3(t.vector(tangent))), 0, atol=1e-12)
    naive = unit3(t.vector(n))                       # the wrong rule, to show the test can tell
    assert np.abs(dot3(naive, unit3(t.vector(t1)))).max() > 1e-3


@pytest.mark.parametrize("m", [
    np.diag([1.0, 0.0, 1.0, 1.0]),
    np.array([[1.0, 2, 3, 0], [2, 4, 6, 1], [0, 0, 1, 0], [0, 0, 0, 1]]),
    np.zeros((4, 4)),
])
def test_singular_matrix_raises_value_error(m):
    """A transform without an inverse is refused with ValueError."""
    with pytest.raises(ValueError, match="singular"):
        tf.Transform.from_matrix(m)


def test_zero_scale_raises_value_error():
    """scale with a 0 factor is singular too."""
    with pytest.raises(ValueError, match="singular"):
        tf.scale([1, 0, 1])


def test_singular_transform_in_yaml_is_a_located_scene_error():
    """Through build, a singular matrix is a SceneError at the step."""
    with pytest.raises(SceneError) as e:
        object_transform("[{matrix: [[1, 2, 3, 0], [2, 4, 6, 0], [0, 0, 1, 0]]}]")
    assert str(e.value) == "scene.yaml:5:26: objects[0].transform[0].matrix: singular transform (determinant 0)"
