"""Tests for the solid shapes: Box (box.py), Cylinder and Cone (quadric.py), Torus (torus.py).

Analytic hits, misses = inf, t_min < t < t_max, unit outward normals (checked
against inside tests written here, independently of the shapes' code), batch ==
one ray at a time, hit points on the surface, spans == intersect, and the error
messages of building shapes from YAML.
"""

import numpy as np
import pytest

from rtcli.errors import SceneError
from rtcli.scenefile import yamlfile
from rtcli.scenefile.objects import shape_from
from rtcli.scenefile.params import Params
from rtcli.shapes.box import Box
from rtcli.shapes.quadric import Cone, Cylinder
from rtcli.shapes.torus import Torus

SHAPES = {
    "box": Box(),
    "box_offset": Box((-1, 0, 2), (3, 0.5, 4)),
    "cylinder": Cylinder(),
    "cylinder_tilted": Cylinder((1, -1, 0.5), (-1, 2, 3), 0.7),
    "tube_open": Cylinder((0, 0, 0), (0, 2, 0), 1.5, capped=False),
    "cone": Cone(),
    "cone_truncated": Cone((0.5, 0, -1), (0, 1, 1), 1.2, 0.4),
    "cone_on_tip": Cone((0, 0, 0), (0, 0, 2), 0.0, 1.0),
    "cone_open": Cone(capped=False),
    "torus": Torus(),
    "torus_fat": Torus(2, 0.8),
}
SOLID = [k for k in SHAPES if k not in ("tube_open", "cone_open")]


# --- geometry written independently of the shapes ---
def _frustum(s, p):
    """Height fraction v along base -> top, distance from the axis, and the radius at v."""
    axis = s.top - s.base
    h = np.linalg.norm(axis)
    along = (p - s.base) @ (axis / h)
    radial = np.linalg.norm(p - s.base - along[:, None] * (axis / h), axis=1)
    v = along / h
    return v, radial, s.radius + (s.top_radius - s.radius) * v, along, h


def _torus_f(s, p):
    return (np.sum(p * p, axis=1) + s.R ** 2 - s.r ** 2) ** 2 - 4 * s.R ** 2 * (p[:, 0] ** 2 + p[:, 1] ** 2)


def inside(s, p):
    if isinstance(s, Box):
        return np.all((p > s.lo) & (p < s.hi), axis=1)
    if isinstance(s, Torus):
        return _torus_f(s, p) < 0
    v, radial, r_v, _, _ = _frustum(s, p)
    if not s.capped:                                    # an open tube: inside its wall
        return radial < r_v
    return (v > 0) & (v < 1) & (radial < r_v)


def residual(s, p, prim):
    """Distance of hit points from the surface named by prim."""
    if isinstance(s, Box):
        return np.abs(np.max(np.abs(p - (s.lo + s.hi) / 2) - (s.hi - s.lo) / 2, axis=1))
    if isinstance(s, Torus):
        rho = np.hypot(p[:, 0], p[:, 1])
        return np.abs(np.hypot(rho - s.R, p[:, 2]) - s.r)
    v, radial, r_v, along, h = _frustum(s, p)
    side = np.abs(radial - r_v) + np.maximum(0, -v) + np.maximum(0, v - 1)
    base = np.abs(along) + np.maximum(0, radial - s.radius)
    top = np.abs(along - h) + np.maximum(0, radial - s.top_radius)
    return np.choose(prim, [side, base, top])


def prims(s, prim, n):
    return np.zeros(n, dtype=np.int64) if prim is None else prim


def rays_from_outside(s, n, seed=0):
    """Origins on a sphere around the bounds, aimed at random points of the (grown) bounds."""
    rng = np.random.default_rng(seed)
    lo, hi = s.bounds()
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    o = rng.normal(size=(n, 3))
    o = centre + 3 * np.linalg.norm(half) * o / np.linalg.norm(o, axis=1)[:, None]
    target = centre + rng.uniform(-1.2, 1.2, (n, 3)) * half
    return o, (target - o) * rng.uniform(0.2, 3, (n, 1))


def random_rays(s, n, seed=1):
    """Half from outside, half starting inside the bounds, any direction."""
    rng = np.random.default_rng(seed)
    o, d = rays_from_outside(s, n, seed)
    lo, hi = s.bounds()
    k = n // 2
    o[:k] = lo + rng.uniform(0, 1, (k, 3)) * (hi - lo)
    d[:k] = rng.normal(size=(k, 3))
    return o, d


def hits_from_outside(s, n=2000):
    o, d = rays_from_outside(s, n)
    t, prim = s.intersect(o, d, 0.0, np.inf)
    hit = np.isfinite(t)
    assert 0.1 < hit.mean() < 0.95
    return o[hit], d[hit], t[hit], prims(s, prim, n)[hit]


# --- every shape ---
@pytest.mark.parametrize("name", SHAPES)
def test_batch_equals_one_ray_at_a_time(name):
    s = SHAPES[name]
    o, d = random_rays(s, 200)
    t_max = np.where(np.arange(200) % 3 == 0, np.inf, np.random.default_rng(2).uniform(0, 20, 200))
    t, prim = s.intersect(o, d, 1e-9, t_max)
    prim = prims(s, prim, 200)
    spans = s.spans(o, d)
    for i in range(200):
        t1, prim1 = s.intersect(o[i:i + 1], d[i:i + 1], 1e-9, t_max[i:i + 1])
        np.testing.assert_array_equal(t1, t[i:i + 1])
        np.testing.assert_array_equal(prims(s, prim1, 1), prim[i:i + 1])
        for whole, one in zip(spans, s.spans(o[i:i + 1], d[i:i + 1])):
            np.testing.assert_array_equal(one, whole[i:i + 1])


@pytest.mark.parametrize("name", SHAPES)
def test_hit_points_lie_on_the_surface(name):
    s = SHAPES[name]
    o, d, t, prim = hits_from_outside(s)
    p = o + t[:, None] * d
    assert residual(s, p, prim).max() < 1e-9
    lo, hi = s.bounds()
    assert np.all((p >= lo - 1e-9) & (p <= hi + 1e-9))


@pytest.mark.parametrize("name", SHAPES)
def test_normals_are_unit_and_outward(name):
    s = SHAPES[name]
    o, d, t, prim = hits_from_outside(s)
    p = o + t[:, None] * d
    n = s.normal(p, prim)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-12)
    assert not inside(s, p + 1e-6 * n).any()
    assert inside(s, p - 1e-6 * n).all()


@pytest.mark.parametrize("name", SHAPES)
def test_misses_are_inf(name):
    s = SHAPES[name]
    o, d = rays_from_outside(s, 500)
    away = -d                                           # from outside the bounding sphere, going away
    t, _ = s.intersect(o, away, 0.0, np.inf)
    assert np.all(t == np.inf)
    t, _ = s.intersect(o + 100 * np.array([0.3, -0.5, 0.8]), d, 0.0, np.inf)   # the line passes far away
    assert np.all(t == np.inf)


@pytest.mark.parametrize("name", SHAPES)
def test_only_t_min_lt_t_lt_t_max(name):
    s = SHAPES[name]
    o, d, t0, _ = hits_from_outside(s)
    t, _ = s.intersect(o, d, 0.0, t0)                   # t < t_max strictly: the hit at t0 is gone
    assert np.all(t == np.inf)
    t, _ = s.intersect(o, d, 0.0, t0 * (1 + 1e-9))
    np.testing.assert_array_equal(t, t0)
    t, _ = s.intersect(o, d, t0, np.inf)                # t > t_min strictly: a later hit or none
    assert np.all(t > t0)
    t_min, t_max = t0 * 0.5, t0 * 1.5
    t, _ = s.intersect(o, -d, -t_max, -t_min)           # negative t allowed by the caller's range
    assert np.all(np.isinf(t) | ((t > -t_max) & (t < -t_min)))


@pytest.mark.parametrize("name", SHAPES)
def test_uv_in_unit_square(name):
    s = SHAPES[name]
    o, d, t, prim = hits_from_outside(s)
    uv = s.uv(o + t[:, None] * d, prim)
    assert uv.shape == (len(t), 2)
    assert np.all((uv >= -1e-12) & (uv <= 1 + 1e-12))


@pytest.mark.parametrize("name", SOLID)
def test_spans_agree_with_intersect(name):
    s = SHAPES[name]
    o, d = random_rays(s, 1000)
    t_in, p_in, t_out, p_out = s.spans(o, d)
    assert t_in.shape == p_in.shape == t_out.shape == p_out.shape and t_in.shape[0] == 1000
    assert np.all(t_in <= t_out) and np.all(t_out[:, :-1] <= t_in[:, 1:])
    assert np.all(np.isinf(t_in) == np.isinf(t_out))
    t, prim = s.intersect(o, d, 0.0, np.inf)
    bounds, which = np.concatenate([t_in, t_out], axis=1), np.concatenate([p_in, p_out], axis=1)
    after = np.where(bounds > 0, bounds, np.inf)
    k = np.argmin(after, axis=1)
    np.testing.assert_array_equal(after[np.arange(1000), k], t)
    hit = np.isfinite(t)
    np.testing.assert_array_equal(which[np.arange(1000), k][hit], prims(s, prim, 1000)[hit])


@pytest.mark.parametrize("name", ["tube_open", "cone_open"])
def test_open_shapes_have_no_spans(name):
    o, d = random_rays(SHAPES[name], 100)
    t_in, _, t_out, _ = SHAPES[name].spans(o, d)
    assert np.all(np.isinf(t_in)) and np.all(np.isinf(t_out))


def one(shape, o, d, t_min=0.0, t_max=np.inf):
    t, prim = shape.intersect(np.array([o], float), np.array([d], float), t_min, t_max)
    prim = np.zeros(1, dtype=np.int64) if prim is None else prim
    p = np.array([o], float) + np.where(np.isfinite(t), t, 0)[:, None] * np.array([d], float)
    n = shape.normal(p, prim) if np.isfinite(t[0]) else np.full((1, 3), np.nan)
    return t[0], int(prim[0]), n[0] / np.linalg.norm(n[0]), p


# --- box ---
def test_box_analytic():
    b = Box()
    t, prim, n, _ = one(b, (5, 0, 0), (-1, 0, 0))
    assert (t, prim) == (4.0, 1) and np.array_equal(n, [1, 0, 0])
    t, prim, n, _ = one(b, (0.5, 0.5, 0), (0, 0, 1))          # from inside: the exit
    assert (t, prim) == (1.0, 5) and np.array_equal(n, [0, 0, 1])
    t, prim, n, _ = one(b, (0, -3, 0), (0, 0.5, 0))
    assert (t, prim) == (4.0, 2) and np.array_equal(n, [0, -1, 0])
    assert one(b, (5, 0, 0), (-1, 0, 0), t_max=4.0)[0] == np.inf
    assert one(b, (5, 0, 0), (-1, 0, 0), t_min=4.0)[0] == 6.0
    assert one(b, (5, 1.5, 0), (-1, 0, 0))[0] == np.inf
    t_in, p_in, t_out, p_out = b.spans(np.array([[5.0, 0, 0]]), np.array([[-1.0, 0, 0]]))
    assert (t_in[0, 0], p_in[0, 0], t_out[0, 0], p_out[0, 0]) == (4.0, 1, 6.0, 0)


def test_box_uv_per_face():
    b = Box((0, 0, 0), (2, 4, 8))
    p = np.array([[2.0, 1, 2], [1, 4, 2], [1, 1, 0]])
    np.testing.assert_allclose(b.uv(p, np.array([1, 3, 4])), [[0.25, 0.25], [0.25, 0.5], [0.5, 0.25]])


# --- cylinder and cone ---
def test_cylinder_generic_analytic():
    c = Cylinder()
    t, prim, n, _ = one(c, (5, 0, 0), (-1, 0, 0))
    assert (t, prim) == (4.0, 0) and np.array_equal(n, [1, 0, 0])
    t, prim, n, _ = one(c, (0, 0, 5), (0, 0, -1))
    assert (t, prim) == (4.0, 2) and np.array_equal(n, [0, 0, 1])
    t, prim, n, _ = one(c, (0.5, 0, -5), (0, 0, 2))
    assert (t, prim) == (2.0, 1) and np.array_equal(n, [0, 0, -1])
    assert one(c, (5, 0, 1.5), (-1, 0, 0))[0] == np.inf       # above the top
    uv = c.uv(np.array([[1.0, 0, 0], [0, 1, -1]]), np.array([0, 0]))
    np.testing.assert_allclose(uv, [[0, 0.5], [0.25, 0]])


def test_open_tube_has_no_caps_and_shows_its_inside():
    c = Cylinder(capped=False)
    assert one(c, (0.5, 0, 5), (0, 0, -1))[0] == np.inf
    t, prim, n, _ = one(c, (0, 0, 0), (1, 0, 0))
    assert (t, prim) == (1.0, 0) and np.array_equal(n, [1, 0, 0])    # outward, seen from inside


def test_cylinder_parametric():
    c = Cylinder((1, 2, 3), (1, 2, 7), 2)
    t, prim, n, p = one(c, (10, 2, 5), (-1, 0, 0))
    assert (t, prim) == (7.0, 0) and np.array_equal(n, [1, 0, 0])
    np.testing.assert_allclose(c.uv(p, np.array([0])), [[0, 0.5]])
    c = Cylinder((0, 0, 0), (3, 0, 0), 1)                     # axis along x
    t, prim, n, p = one(c, (1.5, 5, 0), (0, -1, 0))
    assert (t, prim) == (4.0, 0)
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(c.uv(p, np.array([0]))[0, 1], 0.5)
    t, prim, n, _ = one(c, (-2, 0.3, 0.2), (1, 0, 0))
    assert (t, prim) == (2.0, 1) and np.array_equal(n, [-1, 0, 0])


def test_cone_generic_analytic():
    c = Cone()
    t, prim, n, p = one(c, (5, 0, 0.5), (-1, 0, 0))
    assert (t, prim) == (4.5, 0)
    np.testing.assert_allclose(n, np.array([1, 0, 1]) / np.sqrt(2), rtol=1e-15)
    np.testing.assert_allclose(c.uv(p, np.array([0])), [[0, 0.5]])
    t, prim, n, _ = one(c, (0.2, 0.1, -5), (0, 0, 1))
    assert (t, prim) == (5.0, 1) and np.array_equal(n, [0, 0, -1])
    t, prim, n, _ = one(c, (0, 0, 5), (0, 0, -1))             # the apex
    assert (t, prim) == (4.0, 0) and np.all(np.isfinite(n))
    t, prim, _, _ = one(c, (0.6, 0, 5), (0, 0, -1))          # down beside the apex: the side
    assert prim == 0 and t == pytest.approx(4.6, rel=1e-15)


def test_truncated_cone_has_both_caps():
    c = Cone((0, 0, 0), (0, 0, 2), 2, 1)
    t, prim, n, _ = one(c, (0, 0.5, 5), (0, 0, -1))
    assert (t, prim) == (3.0, 2) and np.array_equal(n, [0, 0, 1])
    t, prim, _, _ = one(c, (10, 0, 1), (-1, 0, 0))
    assert (t, prim) == (8.5, 0)
    t_in, p_in, t_out, p_out = c.spans(np.array([[0, 0.5, 5.0]]), np.array([[0, 0, -1.0]]))
    assert (t_in[0, 0], p_in[0, 0], t_out[0, 0], p_out[0, 0]) == (3.0, 2, 5.0, 1)


# --- torus ---
def test_torus_ray_through_the_hole_misses():
    assert one(Torus(), (0, 0, 5), (0, 0, -1))[0] == np.inf
    assert one(Torus(), (0.5, 0.2, -5), (0, 0, 3))[0] == np.inf


def test_torus_ray_along_x_has_four_hits():
    s = Torus()
    o, d = np.array([[-5.0, 0, 0]]), np.array([[1.0, 0, 0]])
    t, prim = s.intersect(o, d, 0.0, np.inf)
    assert np.array_equal(prim, [0])
    np.testing.assert_allclose(t, [3.75], rtol=1e-14)
    t_in, _, t_out, _ = s.spans(o, d)
    np.testing.assert_allclose(t_in, [[3.75, 5.75]], rtol=1e-14)
    np.testing.assert_allclose(t_out, [[4.25, 6.25]], rtol=1e-14)
    np.testing.assert_allclose(s.intersect(o, d, 4.0, np.inf)[0], [4.25], rtol=1e-14)
    n = s.normal(o + 3.75 * d, None)
    np.testing.assert_allclose(n / np.linalg.norm(n), [[-1, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(s.uv(np.array([[0, 1.25, 0], [-1, 0, 0.25]]), None), [[0.25, 0], [0.5, 0.25]])


@pytest.mark.parametrize("dz", [0.0, 1e-3, -1e-3, 1e-9, -1e-9, -1e-6, 1e-12, -1e-12])
def test_torus_grazing_the_top_of_the_tube(dz):
    s = Torus()
    o, d = np.array([[-5.0, 0, 0.25 + dz]]), np.array([[1.0, 0, 0]])
    t, _ = s.intersect(o, d, 0.0, np.inf)
    spans = s.spans(o, d)
    assert not np.isnan(t).any() and not any(np.isnan(x).any() for x in spans)
    if dz > 0:
        assert t[0] == np.inf
    if dz <= -1e-6:
        assert np.isfinite(t[0])
    if np.isfinite(t[0]):
        p = o + t[:, None] * d
        z = 0.25 + dz                                   # (|x| - R)^2 + z^2 = r^2 on y = 0
        assert abs(p[0, 0] + 1 + np.sqrt(max(0.25 ** 2 - z * z, 0))) < 1e-7
        assert residual(s, p, None) < 1e-9
        assert spans[0][0, 0] == t[0]


def test_torus_far_ray_gives_the_same_hit_point():
    s = Torus()
    c = np.array([[0.6, 0.3, 0.2]]) / np.linalg.norm([0.6, 0.3, 0.2])
    q = np.array([[-0.3, -0.2, 0.1]])
    p_near = q - 10 * c + s.intersect(q - 10 * c, c, 0.0, np.inf)[0][:, None] * c
    p_far = q - 1e4 * c + s.intersect(q - 1e4 * c, c * 3, 0.0, np.inf)[0][:, None] * c * 3
    assert np.all(np.isfinite(p_near))
    np.testing.assert_allclose(p_far, p_near, atol=1e-9)
    assert residual(s, p_far, None) < 1e-9


@pytest.mark.parametrize("minor", [1.0, 1.5])
def test_horn_and_spindle_torus_hits_lie_on_the_quartic(minor):
    s = Torus(1.0, minor)
    o, d = rays_from_outside(s, 500)
    t, _ = s.intersect(o, d, 0.0, np.inf)
    hit = np.isfinite(t)
    p = o[hit] + t[hit, None] * d[hit]
    assert hit.any() and np.abs(_torus_f(s, p)).max() < 1e-9


# --- building from YAML (rtcli.scenefile.objects.shape_from) and its errors ---
def params(text, key):
    tree = yamlfile.parse(text + "\n", "t.yaml")
    return Params(tree[key], f"objects[0].{key}")


def test_built_from_yaml_defaults_and_values():
    assert np.array_equal(shape_from(params("box: {}", "box"), Box).lo, [-1, -1, -1])
    text = "cylinder: {base: [0, 1, 0], top: [0, 3, 0], radius: 0.5, capped: false}"
    c = shape_from(params(text, "cylinder"), Cylinder)
    assert (c.radius, c.top_radius, c.capped, c.h) == (0.5, 0.5, False, 2.0)
    c = shape_from(params("cone: {}", "cone"), Cone)
    assert (c.radius, c.top_radius, c.capped) == (1.0, 0.0, True) and np.array_equal(c.top, [0, 0, 1])
    c = shape_from(params("cone: {radius: 0, top_radius: 2}", "cone"), Cone)
    assert (c.radius, c.top_radius) == (0.0, 2.0)
    t = shape_from(params("torus: {}", "torus"), Torus)
    assert (t.R, t.r) == (1.0, 0.25)
    t = shape_from(params("torus: {major: 3, minor: 4}", "torus"), Torus)
    assert (t.R, t.r) == (3.0, 4.0)


@pytest.mark.parametrize("cls, key, text, message", [
    (Box, "box", "box: {min: [0, 0, 0], max: [1, 0, 1]}",
     "t.yaml:1:28: objects[0].box.max: must be > min in every component, got min [0, 0, 0], max [1, 0, 1]"),
    (Cylinder, "cylinder", "cylinder: {base: [0,0,0], top: [0,0,0], radius: 1}",
     "t.yaml:1:32: objects[0].cylinder.top: must differ from base (the axis has zero length)"),
    (Cylinder, "cylinder", "cylinder: {radius: 0}",
     "t.yaml:1:20: objects[0].cylinder.radius: must be > 0, got 0"),
    (Cylinder, "cylinder", "cylinder: {capped: 1}",
     "t.yaml:1:20: objects[0].cylinder.capped: must be true or false, got 1"),
    (Cone, "cone", "cone: {radius: -1}",
     "t.yaml:1:16: objects[0].cone.radius: must be >= 0, got -1"),
    (Cone, "cone", "cone: {top_radius: -2}",
     "t.yaml:1:20: objects[0].cone.top_radius: must be >= 0, got -2"),
    (Cone, "cone", "cone: {radius: 0, top_radius: 0}",
     "t.yaml:1:31: objects[0].cone.top_radius: radius and top_radius must not both be 0"),
    (Cone, "cone", "cone: {radius: 0}",
     "t.yaml:1:16: objects[0].cone.radius: radius and top_radius must not both be 0"),
    (Cone, "cone", "cone: {base: [1, 2, 3], top: [1, 2, 3]}",
     "t.yaml:1:30: objects[0].cone.top: must differ from base (the axis has zero length)"),
    (Torus, "torus", "torus: {major: 0}", "t.yaml:1:16: objects[0].torus.major: must be > 0, got 0"),
    (Torus, "torus", "torus: {minor: -1}", "t.yaml:1:16: objects[0].torus.minor: must be > 0, got -1"),
])
def test_build_errors(cls, key, text, message):
    with pytest.raises(SceneError) as e:
        shape_from(params(text, key), cls)
    assert str(e.value) == message
