"""Glass (core/dielectric.py): the medium each ray is in, Snell's law between any two media,
total internal reflection dropped or reflected, Fresnel's equations, shadows through glass.

As in test_trace.py, glass has no local term and targets are emission-only strips, so each
pixel is an exact product of weights and a target's emission, and which target a ray reaches
pins its direction.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import DARK, E1, E2, RTOL, f, one_pixel, scene_from_yaml, vec

from rtcli.core.dielectric import fresnel, indices, refracted_media, split
from rtcli.core.materials import Material, MaterialTable


def scene(eye, look_at, objects: str, render: str = "", lights: str = "[]"):
    return scene_from_yaml(f"""
image: {{width: 1, height: 1}}
camera: {{eye: {vec(eye)}, look_at: {vec(look_at)}, fov: 1}}
ambient: [1, 1, 1]
render: {{max_depth: 8{", " + render if render else ""}}}
lights: {lights}
objects:
{objects}
""")


def stripe(x: float, y: float, emission, half: float = 0.01, facing: str = "up") -> str:
    """An emission-only strip |x' - x| <= half, |z| <= 1 in the plane y, facing +y (or -y)."""
    v = [[x - half, y, -1], [x - half, y, 1], [x + half, y, 1], [x + half, y, -1]]
    v = v[::-1] if facing == "down" else v
    return (f"  - {{polygon: {{vertices: [{', '.join(vec(p) for p in v)}]}}, "
            f"material: {{{DARK}, emission: {vec(emission)}}}}}\n")


def slab(y0: float, y1: float, ior: float, half: float = 40.0) -> str:
    """A clear box y0 <= y <= y1, wide in x and z, of index ior."""
    return (f"  - {{box: {{min: {vec([-half, y0, -half])}, max: {vec([half, y1, half])}}}, "
            f"material: {{{DARK}, transmission: 1, ior: {f(ior)}}}}}\n")


def tan_in(sin: float) -> float:
    return sin / np.sqrt(1 - sin * sin)


# --- the medium a ray is in ---
def test_nested_media_bend_by_the_ratio_of_their_indices_and_exit_parallel():
    """Air, glass 1.5 (0 > y > -3) holding water 1.33 (-1 > y > -2), air: a ray entering at 45 deg
    crosses glass at asin(sin 45 / 1.5), water at asin(sin 45 / 1.33) (glass -> water is 1.5 ->
    1.33, not 1 -> 1.33), glass again, and leaves parallel to how it came, reaching y = -4 at
    2 tan(glass) + tan(water) + 1."""
    s45 = np.sin(np.radians(45))
    x = 2 * tan_in(s45 / 1.5) + tan_in(s45 / 1.33) + 1
    wrong = 2 * tan_in(s45 / 1.5) + tan_in(s45 / 1.33 / 1.5 * 1.0) + 1           # water entered from air
    objects = slab(-3, 0, 1.5) + slab(-2, -1, 1.33, half=30) + stripe(x, -4, E1) + stripe(wrong, -4, E2)
    np.testing.assert_allclose(one_pixel(scene((-2, 2, 0), (0, 0, 0), objects)), E1, rtol=RTOL)


@pytest.mark.parametrize("tir", ["drop", "reflect"])
@pytest.mark.parametrize("step", [-1.0, 1.0])
def test_critical_angle_between_glass_and_water(tir, step):
    """The camera in glass (medium_ior 1.5) looks at water 1.33 below y = 0: the critical angle is
    asin(1.33 / 1.5). A degree before it the ray refracts to a strip under water; a degree past
    it nothing is transmitted: dropped (black), or with `reflect` the mirror ray carries kt to a
    strip above."""
    theta = np.degrees(np.arcsin(1.33 / 1.5)) + step
    s = np.sin(np.radians(theta))
    eye = 2 * np.array([-s, np.cos(np.radians(theta)), 0])
    below = stripe(tan_in(1.5 * s / 1.33), -1, E1) if step < 0 else ""
    above = stripe(tan_in(s), 1, E2, facing="down")
    objects = slab(-10, 0, 1.33) + below + above
    got = one_pixel(scene(eye, (0, 0, 0), objects, f"medium_ior: 1.5, total_internal_reflection: {tir}"))
    expected = E1 if step < 0 else (E2 if tir == "reflect" else np.zeros(3))
    np.testing.assert_allclose(got, expected, rtol=RTOL, atol=1e-15)


def test_an_air_bubble_in_glass_bends_rays_away_from_the_normal():
    """Air 1.0 inside glass 1.5: entering the bubble goes 1.5 -> 1.0. Slabs again: glass 0 > y > -3,
    air -1 > y > -2 inside it; at 30 deg the ray crosses the air at asin(sin 30) = 30 deg."""
    s30 = np.sin(np.radians(30))
    x = 2 * tan_in(s30 / 1.5) + tan_in(s30) + tan_in(s30)
    objects = slab(-3, 0, 1.5) + slab(-2, -1, 1.0, half=30) + stripe(x, -4, E1)
    eye = (-2 * s30, 2 * np.cos(np.radians(30)), 0)
    np.testing.assert_allclose(one_pixel(scene(eye, (0, 0, 0), objects)), E1, rtol=RTOL)


def test_media_stack_nested_and_overlapping():
    """Entering pushes, leaving removes the topmost entry of that index, wherever it is."""
    def cross(stack, ior_m, entering):
        ior = np.array(stack + [0.0] * (4 - len(stack)))
        out = np.zeros(4)
        n = refracted_media(ior, len(stack), ior_m, entering, out)
        return list(out[:n])
    assert cross([], 1.5, True) == [1.5]
    assert cross([1.5], 1.33, True) == [1.5, 1.33]
    assert cross([1.5, 1.33], 1.33, False) == [1.5]                 # nested: leave the inner one
    assert cross([1.5, 1.33], 1.5, False) == [1.33]                 # overlapping: leave the outer one
    assert cross([1.5], 2.4, False) == [1.5]                        # leaving what it never entered
    assert indices(np.array([1.5, 1.33, 0, 0]), 2, 1.0, 1.33, False) == (1.33, 1.5)
    assert indices(np.array([1.5, 1.33, 0, 0]), 2, 1.0, 2.4, True) == (1.33, 2.4)
    assert indices(np.array([0.0, 0, 0, 0]), 0, 1.2, 1.5, True) == (1.2, 1.5)        # the scene's medium
    assert indices(np.array([0.0, 0, 0, 0]), 0, 1.2, 1.5, False) == (1.5, 1.2)       # started inside


# --- Fresnel ---
def test_fresnel_at_normal_incidence_brewster_and_beyond_the_critical_angle():
    n1, n2 = 1.0, 1.5
    assert fresnel(1.0, n1 / n2) == pytest.approx(((n1 - n2) / (n1 + n2)) ** 2, rel=1e-14)     # 0.04
    brewster = np.arctan(n2 / n1)                                   # Rp = 0 there: R = Rs / 2
    ci, ct = np.cos(brewster), np.sqrt(1 - (n1 / n2 * np.sin(brewster)) ** 2)
    rs = ((n1 * ci - n2 * ct) / (n1 * ci + n2 * ct)) ** 2
    assert fresnel(ci, n1 / n2) == pytest.approx(rs / 2, rel=1e-12)
    assert fresnel(0.0, n1 / n2) == pytest.approx(1.0)              # grazing
    assert fresnel(np.cos(np.radians(45)), 1.5) == 1.0              # glass -> air past 41.8 deg


def test_fresnel_weights_never_carry_more_light_than_they_get():
    """Across angles and indices, and any kr, kt <= 1: wr + wt <= max(kr, kt); = 1 for kr = kt = 1."""
    rng = np.random.default_rng(3)
    cos_i, eta = rng.uniform(0, 1, 5000), rng.choice([1 / 2.4, 1 / 1.5, 1 / 1.33, 1.33, 1.5, 2.4], 5000)
    kr, kt = rng.uniform(0, 1, (5000, 3)), rng.uniform(0, 1, (5000, 3))
    table = MaterialTable([Material(reflection=a, transmission=b, fresnel=True) for a, b in zip(kr, kt)] +
                          [Material(reflection=np.ones(3), transmission=np.ones(3), fresnel=True)])
    R = fresnel(cos_i, eta)
    tir = 1 - eta * eta * (1 - cos_i * cos_i) < 0
    assert np.all((R >= 0) & (R <= 1)) and np.all(R[tir] == 1)
    wr, wt = split(table, np.arange(5000), R, tir, True)
    assert np.all(np.array(wr) + np.array(wt) <= np.maximum(kr, kt).T + 1e-15)
    one_r, one_t = split(table, np.full(5000, 5000), R, tir, True)
    np.testing.assert_allclose(np.array(one_r) + np.array(one_t), 1.0, rtol=0, atol=1e-15)


def test_a_fresnel_window_reflects_more_at_grazing_angles():
    """A thin glass plate (two polygons) with fresnel: what it shows of a glowing floor behind it is
    the transmitted share (1 - R)^2, plus what bounces inside it, R^2 and R^4 more (rays 3, 5 and 7
    of max_depth 8); at 80 deg off the normal much less than at 10."""
    def seen(theta):
        s, c = np.sin(np.radians(theta)), np.cos(np.radians(theta))
        plate = (f"  - {{polygon: {{vertices: [[-40, 0, -40], [-40, 0, 40], [40, 0, 40], [40, 0, -40]]}}, "
                 f"material: {{{DARK}, transmission: 1, reflection: 1, ior: 1.5, fresnel: true}}}}\n"
                 f"  - {{polygon: {{vertices: [[-40, -0.01, -40], [40, -0.01, -40], [40, -0.01, 40], [-40, -0.01, 40]]}},"
                 f" material: {{{DARK}, transmission: 1, reflection: 1, ior: 1.5, fresnel: true}}}}\n")
        back = "  - {plane: {point: [0, -5, 0]}, material: {ambient: 0, diffuse: 0, emission: [1, 1, 1]}}\n"
        return one_pixel(scene((-3 * s, 3 * c, 0), (0, 0, 0), plate + back))[0]
    for theta in (10, 80):
        R = fresnel(np.cos(np.radians(theta)), 1 / 1.5)
        assert seen(theta) == pytest.approx((1 - R) ** 2 * (1 + R ** 2 + R ** 4), rel=1e-9)
    assert seen(80) < 0.7 * seen(10)


# --- shadows through glass ---
FLOOR = "  - {plane: {}, material: {ambient: 0, diffuse: 1}}\n"
LIGHT = "[{position: [0, 5, 0]}]"


@pytest.mark.parametrize("shadow, factor", [("true", [0, 0, 0]), ("false", [1, 1, 1]),
                                            ("filter", [0.5, 0.8, 1.0])])
def test_a_glass_plate_filters_the_light_by_kt(shadow, factor):
    """The floor under a glass square (one surface) lit from straight above: kd I (N.L) = 1, times
    0 (a full shadow), 1 (none) or kt (filter)."""
    plate = (f"  - {{square: {{}}, material: {{{DARK}, transmission: [0.5, 0.8, 1.0], shadow: {shadow}}}, "
             "transform: [{rotate: {axis: [1, 0, 0], degrees: -90}}, {translate: [0, 2, 0]}]}\n")
    got = one_pixel(scene((6, 1, 0), (0, 0, 0), FLOOR + plate, lights=LIGHT))
    np.testing.assert_allclose(got, factor, rtol=RTOL, atol=1e-15)


def test_a_glass_ball_filters_twice_and_a_wall_behind_it_still_stops_the_light():
    """A filtering sphere is crossed twice: kt^2. An opaque object further along stops the feeler."""
    ball = f"  - {{sphere: {{center: [0, 2.5, 0], radius: 0.5}}, material: {{{DARK}, transmission: 0.5, shadow: filter}}}}\n"
    got = one_pixel(scene((6, 1, 0), (0, 0, 0), FLOOR + ball, lights=LIGHT))
    np.testing.assert_allclose(got, [0.25, 0.25, 0.25], rtol=RTOL)
    wall = "  - {sphere: {center: [0, 4, 0], radius: 0.3}}\n"
    np.testing.assert_array_equal(one_pixel(scene((6, 1, 0), (0, 0, 0), FLOOR + ball + wall, lights=LIGHT)), 0)


def test_shadow_must_be_true_false_or_filter():
    from rtcli.errors import SceneError
    with pytest.raises(SceneError, match=r"material.shadow: must be true, false or filter, got 'glass'"):
        scene((6, 1, 0), (0, 0, 0), "  - {sphere: {}, material: {shadow: glass}}\n")
