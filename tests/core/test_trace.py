"""The global terms of the shading equation: kr * trace(mirror ray), kt * trace(refracted ray),
max_depth, total internal reflection, and Snell's law in rtcli.core.vec.refract.

Mirrors and glass here have no local term (ka = kd = ks = 0), and what they show
is an emission-only target, so each pixel is an exact product of weights and
the target's emission. Which target a ray reaches pins its direction.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import DARK, E1, E2, RTOL, one_pixel, scene_from_yaml, vec

from rtcli.core import vec as vectors
from rtcli.wavefront.intersect import find_first_hit, surface
from rtcli.wavefront.rays import Rays


def scene(eye, look_at, objects: str, max_depth: int = 5, up=(0, 1, 0)):
    return scene_from_yaml(f"""
image: {{width: 1, height: 1}}
camera: {{eye: {vec(eye)}, look_at: {vec(look_at)}, up: {vec(up)}, fov: 1}}
ambient: [1, 1, 1]
render: {{max_depth: {max_depth}}}
objects:
{objects}
""")


def stripe(x: float, y: float, emission, half: float = 0.02, facing: str = "up") -> str:
    """An emission-only strip |x' - x| <= half, |z| <= 1 in the plane y, facing +y (or -y)."""
    v = [[x - half, y, -1], [x - half, y, 1], [x + half, y, 1], [x + half, y, -1]]
    if facing == "down":
        v = v[::-1]
    v = "[" + ", ".join(vec(p) for p in v) + "]"
    return f"  - {{polygon: {{vertices: {v}}}, material: {{{DARK}, emission: {vec(emission)}}}}}\n"


# --- mirror rays ---
MIRROR = """  - {{plane: {{}}, material: {{{dark}, reflection: {kr}}}}}
  - {{plane: {{point: [0, 0, -5], normal: [0, 0, 1]}}, material: {{{dark}, emission: {e}}}}}
"""


def mirror_scene(kr: str, max_depth: int = 5):
    """A floor mirror seen at 45 deg; its mirror ray (0, 1, -1) meets an emissive wall z = -5."""
    return scene((0, 1, 1), (0, 0, 0), MIRROR.format(dark=DARK, kr=kr, e=vec(E1)), max_depth)


def test_mirror_shows_kr_times_what_it_faces():
    """A mirror with kr = 0.5 and no local term shows 0.5 x the wall's emission."""
    np.testing.assert_allclose(one_pixel(mirror_scene("0.5")), 0.5 * E1, rtol=RTOL)


def test_mirror_weight_is_per_channel():
    """kr = [0.5, 0.25, 1] weighs each channel of the reflected color."""
    np.testing.assert_allclose(one_pixel(mirror_scene("[0.5, 0.25, 1.0]")),
                               [0.5 * E1[0], 0.25 * E1[1], E1[2]], rtol=RTOL)


def test_mirror_ray_that_escapes_shows_the_background():
    """A mirror ray that hits nothing returns the background color, weighted by kr."""
    s = scene_from_yaml(f"""
image: {{width: 1, height: 1}}
camera: {{eye: [0, 1, 1], look_at: [0, 0, 0], fov: 1}}
background: [0.3, 0.6, 0.9]
objects:
  - {{plane: {{}}, material: {{{DARK}, reflection: [0.5, 0.25, 1.0]}}}}
""")
    np.testing.assert_allclose(one_pixel(s), [0.15, 0.15, 0.9], rtol=RTOL)


def test_local_and_mirror_terms_add():
    """A lit diffuse mirror shows its own kd I (N.L) (N.L = cos 45 deg) plus kr x the wall's color."""
    objects = MIRROR.format(dark="ambient: 0, diffuse: 0.4", kr="0.5", e=vec(E1))
    text = f"""
image: {{width: 1, height: 1}}
camera: {{eye: [0, 1, 1], look_at: [0, 0, 0], fov: 1}}
ambient: [1, 1, 1]
lights: [{{position: [0, 2, 2]}}]
objects:
{objects}"""
    # the wall (kd = 0.4 too) is lit as well, but its emission is what the mirror ray sees plus
    # its own diffuse term at (0, 5, -5): N = +z, L toward (0, 2, 2) = (0, -3, 7)/sqrt(58)
    wall = E1 + 0.4 * 7 / np.sqrt(58)
    np.testing.assert_allclose(one_pixel(scene_from_yaml(text)), 0.4 * np.sqrt(0.5) + 0.5 * wall, rtol=RTOL)


def test_max_depth_1_disables_reflection():
    """max_depth 1 counts the primary ray only: no mirror ray, the mirror is black."""
    np.testing.assert_array_equal(one_pixel(mirror_scene("0.5", max_depth=1)), [0, 0, 0])


CORRIDOR = """  - {{plane: {{}}, material: {{{dark}, reflection: 0.5}}}}
  - {{plane: {{point: [0, 2, 0], normal: [0, -1, 0]}}, material: {{{dark}, reflection: 0.8}}}}
  - {{plane: {{point: [0, 0, -4], normal: [0, 0, 1]}}, material: {{{dark}, emission: {e}}}}}
"""


@pytest.mark.parametrize("max_depth, weight", [(1, 0.0), (2, 0.0), (3, 0.5 * 0.8), (4, 0.5 * 0.8)])
def test_max_depth_counts_rays_per_path(max_depth, weight):
    """floor (ray 1) -> ceiling (ray 2) -> wall (ray 3): the wall shows only when max_depth >= 3."""
    s = scene((0, 1, 0), (0, 0, -1), CORRIDOR.format(dark=DARK, e=vec(E1)), max_depth)
    np.testing.assert_allclose(one_pixel(s), weight * E1, rtol=RTOL, atol=0)


# --- refraction through a slab -1 <= y <= 0 made of two polygons with outward normals ---
TOP = [[-5, 0, -5], [-5, 0, 5], [5, 0, 5], [5, 0, -5]]          # counter-clockwise from +y: normal +y
BOTTOM = [[-5, -1, -5], [5, -1, -5], [5, -1, 5], [-5, -1, 5]]   # normal -y


def slab(kt="1", ior=1.5) -> str:
    glass = f"{{{DARK}, transmission: {kt}, ior: {ior}}}"
    return (f"  - {{polygon: {{vertices: {TOP}}}, material: {glass}}}\n"
            f"  - {{polygon: {{vertices: {BOTTOM}}}, material: {glass}}}\n")


def slab_exit_x(theta1_deg: float, ior: float = 1.5, below: float = 1.0) -> float:
    """Where a ray hitting the slab's top at the origin, theta1 off the normal, meets y = -1 - below.

    Inside: sin theta2 = sin theta1 / ior, across the thickness 1; below the slab it
    leaves parallel to its incoming direction (the slab's faces are parallel).
    """
    s1 = np.sin(np.radians(theta1_deg))
    s2 = s1 / ior
    return s2 / np.sqrt(1 - s2 * s2) + below * s1 / np.sqrt(1 - s1 * s1)


def test_slab_at_normal_incidence_passes_straight():
    """Straight down through the slab: the strip right below is seen, weighted kt twice."""
    objects = slab("[0.5, 0.8, 1.0]") + stripe(0.0, -2.0, E1)
    s = scene((0, 3, 0), (0, 0, 0), objects, up=(0, 0, -1))
    np.testing.assert_allclose(one_pixel(s), np.array([0.25, 0.64, 1.0]) * E1, rtol=RTOL)


def test_slab_displaces_an_oblique_ray_by_snell():
    """At 45 deg the ray reaches y = -2 at tan(theta2) + 1 (Snell), not at 2 (straight on)."""
    x_snell = slab_exit_x(45.0)
    assert x_snell == pytest.approx(1.0 + (np.sqrt(0.5) / 1.5) / np.sqrt(1 - 0.5 / 2.25))
    objects = slab() + stripe(x_snell, -2.0, E1) + stripe(2.0, -2.0, E2)
    np.testing.assert_allclose(one_pixel(scene((-2, 2, 0), (0, 0, 0), objects)), E1, rtol=RTOL)


def test_slab_without_glass_shows_the_straight_on_strip():
    """Control for the test above: with ior 1 the ray goes straight to x = 2."""
    objects = slab(ior=1.0) + stripe(slab_exit_x(45.0), -2.0, E1) + stripe(2.0, -2.0, E2)
    np.testing.assert_allclose(one_pixel(scene((-2, 2, 0), (0, 0, 0), objects)), E2, rtol=RTOL)


def test_entering_is_decided_by_the_outward_normal():
    """entering = d . outward normal < 0: top face from above yes, bottom face from inside no, from below yes."""
    s = scene((0, 3, 0), (0, 0, 0), slab(), up=(0, 0, -1))
    rays = Rays.from_rows(np.array([[0.0, 3, 0], [0.0, -0.5, 0], [0.0, -3, 0]]),
                np.array([[0.3, -1, 0], [0.3, -1, 0], [0.3, 1, 0]]))
    hits = find_first_hit(s, rays)
    np.testing.assert_array_equal(hits.obj, [0, 1, 1])
    sf = surface(s, rays, hits)
    np.testing.assert_array_equal(sf.entering, [True, False, True])
    np.testing.assert_allclose(sf.n.T, [[0, 1, 0], [0, 1, 0], [0, -1, 0]], atol=1e-15)


# --- total internal reflection: the eye inside the glass, looking up at the top face ---
def inside_view(theta_deg: float, ceiling_x: float):
    """Eye at (0, -0.5, 0) in the slab, looking theta off +y toward +x; a strip on the ceiling y = 3."""
    a = np.radians(theta_deg)
    eye = np.array([0.0, -0.5, 0.0])
    objects = slab() + stripe(ceiling_x, 3.0, E1, facing="down")
    return one_pixel(scene(eye, eye + [np.sin(a), np.cos(a), 0.0], objects))


def leaving_x(theta_deg: float) -> float:
    """Where a ray from (0, -0.5, 0) at theta in glass 1.5 meets y = 3 after leaving at y = 0."""
    s1 = np.sin(np.radians(theta_deg))
    s2 = 1.5 * s1                                                 # n1 sin t1 = n2 sin t2, n1 = 1.5, n2 = 1
    return 0.5 * s1 / np.sqrt(1 - s1 * s1) + 3 * s2 / np.sqrt(1 - s2 * s2)


CRITICAL = np.degrees(np.arcsin(1 / 1.5))                         # 41.81 deg


@pytest.mark.parametrize("theta", [30.0, CRITICAL - 0.5])
def test_leaving_glass_below_the_critical_angle_refracts_by_snell(theta):
    """From inside (eta = ior / 1) below the critical angle, the ray leaves bent away from the normal."""
    np.testing.assert_allclose(inside_view(theta, leaving_x(theta)), E1, rtol=RTOL)


@pytest.mark.parametrize("theta", [CRITICAL + 0.5, 60.0])
def test_total_internal_reflection_has_no_refracted_term(theta):
    """Beyond the critical angle no refracted ray is traced: with kr = 0 the pixel is black."""
    objects = slab() + "  - {plane: {point: [0, 3, 0], normal: [0, -1, 0]}, material: {ambient: 0, " \
                       "diffuse: 0, emission: [1, 1, 1]}}\n"
    a = np.radians(theta)
    eye = np.array([0.0, -0.5, 0.0])
    s = scene(eye, eye + [np.sin(a), np.cos(a), 0.0], objects)
    np.testing.assert_array_equal(one_pixel(s), [0, 0, 0])


# --- rtcli.core.vec.refract directly ---
def refract(d, n, eta):
    """The refract kernel on (n, 3) rows: (unit directions (n, 3), tir (n,))."""
    *t, tir = vectors.refract(*vectors.split(d), *vectors.split(n), eta)
    return vectors.stack(*t), tir


def frames(k: int, seed: int):
    """k random orthonormal pairs (n, tangent)."""
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(k, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    t = np.cross(n, rng.normal(size=(k, 3)))
    t /= np.linalg.norm(t, axis=1)[:, None]
    return n, t


@pytest.mark.parametrize("eta", [1 / 1.5, 1 / 1.33, 1.5, 1.0])
def test_refract_obeys_snell(eta):
    """Snell: sin(theta2) = eta sin(theta1) (eta = n1 / n2), unit, in the plane of d and n, on random frames."""
    n, tangent = frames(200, seed=1)
    limit = np.pi / 2 if eta <= 1 else np.arcsin(1 / eta)
    theta1 = np.linspace(0, 0.999 * limit, 200)
    d = np.sin(theta1)[:, None] * tangent - np.cos(theta1)[:, None] * n
    t, tir = refract(d, n, np.full(200, eta))
    assert not tir.any()
    sin2 = eta * np.sin(theta1)
    expected = sin2[:, None] * tangent - np.sqrt(1 - sin2 * sin2)[:, None] * n
    np.testing.assert_allclose(t, expected, atol=1e-12)


def test_refract_tir_mask_switches_at_the_critical_angle():
    """From glass 1.5 into air (eta = 1.5), tir is set exactly beyond asin(1 / 1.5)."""
    n, tangent = frames(4, seed=2)
    theta1 = np.arcsin(1 / 1.5) + np.array([-1e-6, -1e-9, 1e-9, 1e-6])
    d = np.sin(theta1)[:, None] * tangent - np.cos(theta1)[:, None] * n
    _, tir = refract(d, n, np.full(4, 1.5))
    np.testing.assert_array_equal(tir, [False, False, True, True])


def test_refract_at_normal_incidence_keeps_the_direction():
    """theta1 = 0: the ray goes straight on, whatever eta."""
    n, _ = frames(3, seed=3)
    t, tir = refract(-n, n, np.array([1 / 1.5, 1.5, 1 / 2.4]))
    assert not tir.any()
    np.testing.assert_allclose(t, -n, atol=1e-15)
