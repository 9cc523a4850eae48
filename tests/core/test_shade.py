"""The local shading equation of SCENE_FORMAT.md, pinned on one-pixel scenes.

    color = emission + ka Ia T + sum over lights not in shadow with N.L > 0:
                                 att(r) I (kd T (N.L) + ks spec)

Each scene is a 1x1 image whose single (centre) ray hits the floor y = 0 at a
known point P, seen from a known angle, lit by point lights at known angles and
distances, so N, L, V, R, H and r are known in closed form. Expected values are
written from those angles, not from the renderer's vectors.
"""

from __future__ import annotations

import numpy as np
from helpers import one_pixel, scene_from_yaml

from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.rays import camera_rays

RTOL = 1e-9
COS30, COS60, COS15 = np.cos(np.radians(30)), 0.5, np.cos(np.radians(15))


def f(x: float) -> str:
    """A float written so YAML reads it back as the same float."""
    return format(float(x), ".17f")


def vec(v) -> str:
    return "[" + ", ".join(f(x) for x in v) + "]"


def light_at(point, degrees, r, plane="x", color=None, attenuation=None) -> str:
    """A point light at distance r from `point`, `degrees` off the floor's normal +y.

    plane "x": tilted toward +x; plane "-z": tilted toward -z. Then L = the unit
    vector at that angle and N.L = cos(degrees).
    """
    a = np.radians(degrees)
    offset = (np.sin(a), np.cos(a), 0.0) if plane == "x" else (0.0, np.cos(a), -np.sin(a))
    pos = np.asarray(point, float) + r * np.asarray(offset)
    text = f"{{position: {vec(pos)}"
    if color is not None:
        text += f", color: {vec(color)}"
    if attenuation is not None:
        text += f", attenuation: {vec(attenuation)}"
    return text + "}"


def floor_scene(material: str, lights=(), *, point=(0.0, 0.0, 0.0), view_deg=30.0,
                ambient=(0.0, 0.0, 0.0), extra: str = "", render: str = ""):
    """The floor y = 0 seen at `point` from `view_deg` off its normal, on the -x side.

    V = (-sin view_deg, cos view_deg, 0); N = +y.
    """
    a = np.radians(view_deg)
    p = np.asarray(point, float)
    eye = p + 4.0 * np.array([-np.sin(a), np.cos(a), 0.0])
    text = f"""
image: {{width: 1, height: 1}}
camera: {{eye: {vec(eye)}, look_at: {vec(p)}, up: [0, 1, 0], fov: 10}}
ambient: {vec(ambient)}
{render}
lights: [{", ".join(lights)}]
objects:
  - plane: {{}}
    material: {material}
{extra}
"""
    return scene_from_yaml(text)


def check(scene, expected):
    np.testing.assert_allclose(one_pixel(scene), expected, rtol=RTOL, atol=0)


# --- ambient and emission ---
def test_ambient_only_without_lights():
    """No lights: color = emission + ka * Ia (T = 1), per channel."""
    scene = floor_scene("{ambient: [0.1, 0.2, 0.3], diffuse: 0.9, specular: 0.5}",
                        ambient=(0.5, 0.25, 1.0))
    check(scene, [0.05, 0.05, 0.3])


def test_emission_is_added_as_is():
    """Emission is added unscaled (values above 1 included) to ambient and diffuse."""
    scene = floor_scene("{ambient: 0.2, diffuse: 0.4, emission: [0.3, 0.7, 2.0]}",
                        [light_at((0, 0, 0), 60, 3)], ambient=(0.5, 0.5, 0.5))
    check(scene, np.array([0.3, 0.7, 2.0]) + 0.2 * 0.5 + 0.4 * COS60)


# --- diffuse, specular, attenuation ---
def test_lambert_term_is_kd_I_cos():
    """Diffuse: kd * I * (N.L) with N.L = cos 60 = 0.5, plus ka * Ia."""
    scene = floor_scene("{ambient: [0.1, 0.1, 0.2], diffuse: [0.6, 0.5, 0.4]}",
                        [light_at((0, 0, 0), 60, 3)], ambient=(0.5, 0.5, 0.5))
    check(scene, np.array([0.05, 0.05, 0.1]) + np.array([0.6, 0.5, 0.4]) * COS60)


def test_phong_specular_is_cos_RV_to_the_n():
    """Phong: ks (R.V)^n; L at +60 deg, V at -30 deg, so R (at -60) makes 30 deg with V."""
    scene = floor_scene("{ambient: 0, diffuse: 0.5, specular: [0.7, 0.6, 0.5], shininess: 7}",
                        [light_at((0, 0, 0), 60, 3)])
    expected = 0.5 * COS60 + np.array([0.7, 0.6, 0.5]) * COS30 ** 7
    check(scene, expected)


def test_blinn_specular_is_cos_NH_to_the_n_and_differs_from_phong():
    """Blinn: ks (N.H)^n, H halfway between L (+60 deg) and V (-30 deg), at +15 deg."""
    material = "{ambient: 0, diffuse: 0.5, specular: [0.7, 0.6, 0.5], shininess: 7}"
    lights = [light_at((0, 0, 0), 60, 3)]
    blinn = one_pixel(floor_scene(material, lights, render="render: {specular: blinn}"))
    phong = one_pixel(floor_scene(material, lights, render="render: {specular: phong}"))
    np.testing.assert_allclose(blinn, 0.5 * COS60 + np.array([0.7, 0.6, 0.5]) * COS15 ** 7, rtol=RTOL)
    np.testing.assert_allclose(phong, 0.5 * COS60 + np.array([0.7, 0.6, 0.5]) * COS30 ** 7, rtol=RTOL)
    assert np.all(blinn - phong > 0.05)


def test_specular_vanishes_when_R_points_away_from_V():
    """spec = max(0, R.V)^n: V and R 120 deg apart (R.V < 0) give no specular, even for even n."""
    scene = floor_scene("{ambient: 0, diffuse: 0.5, specular: 1, shininess: 2}",
                        [light_at((0, 0, 0), -60, 3)], view_deg=60)
    # L at -60 (the eye's side), R at +60, V at -60: R.V = cos 120 = -0.5 -> 0
    check(scene, [0.5 * COS60] * 3)


def test_attenuation_is_one_over_quadratic_in_r():
    """att(r) = 1 / (c0 + c1 r + c2 r^2) with r = 4: 1 / (0.5 + 1 + 2)."""
    scene = floor_scene("{ambient: 0, diffuse: [0.8, 0.6, 0.4], specular: 0.3, shininess: 5}",
                        [light_at((0, 0, 0), 60, 4, attenuation=(0.5, 0.25, 0.125))])
    att = 1 / (0.5 + 0.25 * 4 + 0.125 * 16)
    check(scene, att * (np.array([0.8, 0.6, 0.4]) * COS60 + 0.3 * COS30 ** 5))


# --- lights: several, colored ---
def test_several_lights_add():
    """Two lights: their terms add (each with its own N.L, color and attenuation)."""
    lights = [light_at((0, 0, 0), 60, 3, color=(1.0, 0.5, 0.25)),
              light_at((0, 0, 0), 45, 2, plane="-z", color=(0.5, 1.0, 2.0), attenuation=(0, 0, 1))]
    scene = floor_scene("{ambient: 0.1, diffuse: 0.6}", lights, ambient=(1.0, 1.0, 1.0))
    cos45 = np.cos(np.radians(45))
    expected = 0.1 + 0.6 * COS60 * np.array([1.0, 0.5, 0.25]) + 0.6 * cos45 / 4 * np.array([0.5, 1.0, 2.0])
    check(scene, expected)


def test_colored_light_multiplies_per_channel():
    """I = [1, 0.5, 0.25] scales diffuse and specular channel by channel."""
    scene = floor_scene("{ambient: 0, diffuse: [0.8, 0.8, 0.8], specular: [0.2, 0.4, 0.6], shininess: 3}",
                        [light_at((0, 0, 0), 60, 3, color=(1.0, 0.5, 0.25))])
    I = np.array([1.0, 0.5, 0.25])
    check(scene, I * (0.8 * COS60 + np.array([0.2, 0.4, 0.6]) * COS30 ** 3))


# --- texture ---
def test_texture_modulates_ambient_and_diffuse_but_not_specular():
    """T multiplies ka Ia and kd (N.L), not ks spec; the checker cell is chosen by position."""
    c1, c2 = np.array([1.0, 0.5, 0.25]), np.array([0.2, 0.4, 0.8])
    material = ("{ambient: 0.3, diffuse: 0.6, specular: 0.5, shininess: 4, "
                "texture: {checker: {colors: [[1, 0.5, 0.25], [0.2, 0.4, 0.8]], size: 1}}}")
    for point, T in (((0.5, 0.0, 0.5), c1), ((1.5, 0.0, 0.5), c2)):
        scene = floor_scene(material, [light_at(point, 60, 3)], point=point, ambient=(0.5, 0.5, 0.5))
        check(scene, 0.3 * 0.5 * T + 0.6 * T * COS60 + 0.5 * COS30 ** 4)


# --- shadows and the N.L rule ---
OCCLUDER = """  - sphere: {{center: {center}, radius: 0.2}}
    material: {material}"""


def occluder(material="{diffuse: 1}"):
    """A small sphere halfway between P = 0 and the light at 60 deg, distance 3."""
    mid = 1.5 * np.array([np.sin(np.radians(60)), COS60, 0.0])
    return OCCLUDER.format(center=vec(mid), material=material)


def test_shadowed_point_gets_ambient_only():
    """An object on the feeler between hit and light removes diffuse and specular."""
    scene = floor_scene("{ambient: 0.25, diffuse: 0.6, specular: 0.5, emission: [0.01, 0.01, 0.01]}",
                        [light_at((0, 0, 0), 60, 3)], ambient=(0.4, 0.4, 0.4), extra=occluder())
    check(scene, [0.01 + 0.25 * 0.4] * 3)


def test_shadow_false_material_casts_no_shadow():
    """The same occluder with `shadow: false` lets the light through."""
    scene = floor_scene("{ambient: 0.25, diffuse: 0.6}", [light_at((0, 0, 0), 60, 3)],
                        ambient=(0.4, 0.4, 0.4), extra=occluder("{diffuse: 1, shadow: false}"))
    check(scene, [0.25 * 0.4 + 0.6 * COS60] * 3)


def test_transparent_objects_cast_full_shadows():
    """A clear glass occluder (kt = 1, ior 1.5) still blocks the light completely, as in the notes."""
    glass = "{ambient: 0, diffuse: 0, transmission: 1, ior: 1.5}"
    scene = floor_scene("{ambient: 0.25, diffuse: 0.6}", [light_at((0, 0, 0), 60, 3)],
                        ambient=(0.4, 0.4, 0.4), extra=occluder(glass))
    check(scene, [0.25 * 0.4] * 3)


def test_objects_beyond_the_light_cast_no_shadow():
    """Only hits with epsilon < t < 1 on the feeler p + t (l - p) count: an object past the light does not."""
    far = 4.5 * np.array([np.sin(np.radians(60)), COS60, 0.0])           # on the feeler's line, t = 1.5
    extra = OCCLUDER.format(center=vec(far), material="{diffuse: 1}")
    scene = floor_scene("{ambient: 0.25, diffuse: 0.6}", [light_at((0, 0, 0), 60, 3)],
                        ambient=(0.4, 0.4, 0.4), extra=extra)
    check(scene, [0.25 * 0.4 + 0.6 * COS60] * 3)


def test_checker_is_evaluated_in_object_space():
    """Translating the floor by 1 along x swaps the checker cell seen at a fixed world point."""
    material = "{ambient: 1, diffuse: 0, texture: {checker: {colors: [[1, 0.5, 0.25], [0.2, 0.4, 0.8]]}}}"
    point = (0.5, 0.0, 0.5)
    plain = floor_scene(material, point=point, ambient=(1, 1, 1))
    moved = floor_scene(material, point=point, ambient=(1, 1, 1),
                        extra="    transform: [{translate: [1, 0, 0]}]")
    check(plain, [1, 0.5, 0.25])
    check(moved, [0.2, 0.4, 0.8])


def test_light_behind_the_surface_contributes_nothing():
    """N.L <= 0 (light below the floor, which casts no shadow here): ambient only, never negative."""
    below = "{position: [1, -3, 0]}"
    scene = floor_scene("{ambient: 0.25, diffuse: 0.6, specular: 0.5, shadow: false}", [below],
                        ambient=(0.4, 0.4, 0.4))
    check(scene, [0.25 * 0.4] * 3)


def test_normal_is_turned_to_face_the_ray():
    """Seen from below, the floor's N is -y, so a light below lights it: kd I cos 60."""
    text = f"""
image: {{width: 1, height: 1}}
camera: {{eye: {vec((-2 * np.sin(np.radians(30)), -2 * COS30, 0))}, look_at: [0, 0, 0], fov: 10}}
ambient: [0, 0, 0]
lights: [{{position: {vec((3 * np.sin(np.radians(60)), -3 * COS60, 0))}}}]
objects:
  - {{plane: {{}}, material: {{ambient: 0, diffuse: 0.6}}}}
"""
    check(scene_from_yaml(text), [0.6 * COS60] * 3)


CONTACT = """
image: {{width: 1, height: 1}}
camera: {{eye: {eye}, look_at: {target}, up: [0, 1, 0], fov: 1}}
ambient: [0, 0, 0]
lights: [{{position: [0, 5, 0]}}]
objects:
  - {{plane: {{}}, material: {{ambient: 0, diffuse: 1}}}}
  - {{sphere: {{center: [0, 1, 0], radius: 1}}, material: {{ambient: 0, diffuse: 1}}}}
"""


def floor_beside_ball(x: float) -> np.ndarray:
    """The floor point (x, 0, 0) under a unit ball resting on the floor at the origin, lit from (0, 5, 0).

    Seen from the +x side at a slope of x / 2, low enough to pass under the ball.
    """
    target = np.array([x, 0.0, 0.0])
    eye = target + np.array([10.0, 5.0 * x, 0.0])
    scene = scene_from_yaml(CONTACT.format(eye=vec(eye), target=vec(target)))
    rays = camera_rays(scene.camera(1, 1), np.array([0.5]), np.array([0.5]), 1, 1)
    hits = find_first_hit(scene, rays)
    assert hits.obj[0] == 0, "the camera must see the floor, not the ball"
    np.testing.assert_allclose(rays.at(hits.t)[:, 0], target, atol=1e-12)
    return one_pixel(scene)


def test_no_light_leaks_under_a_ball_at_its_contact_point():
    """Floor points beside the contact point lie in the ball's shadow (radius 5/sqrt(15)): black."""
    for x in (0.002, 0.01, 0.05, 0.2, 1.0, 1.2):
        np.testing.assert_array_equal(floor_beside_ball(x), [0.0, 0.0, 0.0], err_msg=f"x = {x}")


def test_floor_far_from_the_ball_is_lit():
    """Outside the shadow, at (3, 0, 0): kd I N.L with N.L = 5 / sqrt(34)."""
    np.testing.assert_allclose(floor_beside_ball(3.0), [5 / np.sqrt(34)] * 3, rtol=RTOL)
