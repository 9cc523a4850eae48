"""Sphere and the flat shapes (plane, triangle flat and smooth, polygon convex and not, square).

Analytic hits, misses are inf, t_min < t < t_max, batch == one ray at a time
(exact), unit outward normals under random transforms (mirrors included), and
pbrt's re-intersection test: rays spawned from a hit as rtcli.wavefront.trace spawns them
never hit the same surface again right away.
"""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.core import transform as tf
from rtcli.core.materials import Material, MaterialTable
from rtcli.core.scene import Scene, SceneObject
from rtcli.shapes.plane import Plane
from rtcli.shapes.polygon import Polygon
from rtcli.shapes.sphere import Sphere
from rtcli.shapes.square import Square
from rtcli.shapes.triangle import Triangle
from rtcli.wavefront.intersect import find_first_hit, surface
from rtcli.wavefront.rays import Rays


def _star():
    """The pentagram {5/2}: vertices k * 144 deg around the circle, so it crosses itself."""
    a = np.radians(90 + 144 * np.arange(5))
    return np.stack([np.cos(a), np.sin(a), np.zeros(5)], axis=1)


def _hexagon_tilted():
    """A regular hexagon of radius 1.5 around (1, -1, 2) in the plane with normal (1, 2, 2)/3."""
    n = np.array([1.0, 2, 2]) / 3
    e1 = np.array([2.0, -1, 0]) / np.sqrt(5)
    e2 = np.cross(n, e1)
    a = np.radians(60 * np.arange(6))
    return np.array([1.0, -1, 2]) + 1.5 * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)


L_SHAPE = [[0, 0, 1], [2, 0, 1], [2, 1, 1], [1, 1, 1], [1, 2, 1], [0, 2, 1]]
SMOOTH_NORMALS = [[0.3, 0, 1], [0, -0.4, 1], [-0.2, 0.2, 1]]

SHAPES = {
    "sphere": Sphere(),
    "sphere_offset": Sphere((1, 2, 3), 2.0),
    "plane": Plane(),
    "plane_tilted": Plane((1, 2, 3), (1, 1, -1)),
    "triangle": Triangle((1, 0, 0.5), (3, 0.5, 0), (1, 2, 1)),
    "triangle_smooth": Triangle((0, 0, 0), (2, 0, 0), (0, 2, 0), normals=SMOOTH_NORMALS),
    "polygon_convex": Polygon(_hexagon_tilted()),
    "polygon_L": Polygon(L_SHAPE),
    "pentagram": Polygon(_star()),
    "square": Square(),
}
PLANAR = [k for k in SHAPES if not k.startswith("sphere")]


def one_ray(shape, o, d, t_min=0.0, t_max=np.inf):
    t, _ = shape.intersect(np.array([o], float), np.array([d], float), t_min, t_max)
    return t[0]


# --- analytic hits and misses ---
def test_sphere_analytic_hits():
    """|S + c t - C|^2 = r^2: t = (10 - r)/|c| from outside, r/|c| from the centre; misses are inf."""
    s = Sphere((1, 2, 3), 2.0)
    assert one_ray(s, (1, 2, 13), (0, 0, -2)) == 4.0                 # (10 - 2) / 2
    assert one_ray(s, (1, 2, 3), (3, 0, 0)) == pytest.approx(2 / 3, rel=1e-15)
    h = np.sqrt(4 - 1.999 ** 2)                                      # just inside the rim
    assert one_ray(s, (1 + 1.999, 2, 13), (0, 0, -1)) == pytest.approx(10 - h, rel=1e-12)
    assert one_ray(s, (1 + 2.001, 2, 13), (0, 0, -1)) == np.inf      # passes just beside
    assert one_ray(s, (1, 2, 13), (0, 0, 1)) == np.inf               # sphere behind the ray


def test_sphere_t_range_is_open():
    """Roots 8 and 12: t_min between them gives the far root; t = t_min or t = t_max is excluded."""
    s = Sphere((0, 0, 0), 2.0)
    o, d = (0, 0, 10), (0, 0, -1)
    assert one_ray(s, o, d) == 8.0
    assert one_ray(s, o, d, t_min=9.0) == 12.0
    assert one_ray(s, o, d, t_min=8.0) == 12.0
    assert one_ray(s, o, d, t_min=12.0) == np.inf
    assert one_ray(s, o, d, t_max=8.0) == np.inf
    assert one_ray(s, o, d, t_max=8.0 + 1e-9) == 8.0
    assert one_ray(s, o, d, t_min=9.0, t_max=12.0) == np.inf


def test_plane_analytic_hits():
    """(P - p0).n = 0: t = (p0.n - S.n)/(c.n); parallel or receding rays miss."""
    p = Plane((0, 1, 0), (0, 1, 0))
    assert one_ray(p, (3, 5, -1), (1, -2, 0.5)) == 2.0
    assert one_ray(p, (3, -3, -1), (0, 0.5, 0)) == 8.0               # from below: planes are two-sided
    assert one_ray(p, (3, 5, -1), (1, 0, 0)) == np.inf
    assert one_ray(p, (3, 5, -1), (0, 1, 0)) == np.inf
    tilted = Plane((1, 2, 3), (1, 1, -1))
    assert one_ray(tilted, (1, 2, 3 + 6), (0, 0, -1)) == pytest.approx(6.0, rel=1e-15)


def test_triangle_analytic_hits():
    """A ray through a + alpha (b - a) + beta (c - a) hits where alpha, beta >= 0, alpha + beta <= 1."""
    tri = Triangle((1, 0, 2), (3, 0, 2), (1, 2, 2))
    assert one_ray(tri, (1.5, 0.5, 7), (0, 0, -1)) == 5.0
    assert one_ray(tri, (1.5, 0.5, -3), (0, 0, 2)) == 2.5            # from behind: also a hit
    assert one_ray(tri, (2.5, 1.5, 7), (0, 0, -1)) == np.inf         # alpha + beta = 1.5
    assert one_ray(tri, (0.5, 0.5, 7), (0, 0, -1)) == np.inf         # alpha < 0
    assert one_ray(tri, (1.5, 0.5, 7), (1, 0, 0)) == np.inf          # parallel


def test_smooth_triangle_interpolates_normals():
    """Shading normal = normalize((1 - a - b) na + a nb + b nc) at barycentrics (a, b) = (0.25, 0.5)."""
    shape = SHAPES["triangle_smooth"]
    s = scene_of(shape)
    rays = Rays.from_rows(np.array([[0.5, 1.0, 3.0]]), np.array([[0.0, 0, -1]]))
    sf = surface(s, rays, find_first_hit(s, rays))
    na, nb, nc = (np.array(n) / np.linalg.norm(n) for n in SMOOTH_NORMALS)
    n = 0.25 * na + 0.25 * nb + 0.5 * nc
    np.testing.assert_allclose(sf.n.T[0], n / np.linalg.norm(n), atol=1e-14)
    np.testing.assert_allclose(sf.ng.T[0], [0, 0, 1], atol=1e-15)


def test_convex_polygon_in_a_tilted_plane():
    """Regular hexagon, radius 1.5 (inradius 1.299): 1.4 toward a corner is in, toward an edge is out."""
    hexagon = SHAPES["polygon_convex"]
    c, n = np.array([1.0, -1, 2]), np.array([1.0, 2, 2]) / 3
    e1 = np.array([2.0, -1, 0]) / np.sqrt(5)
    e2 = np.cross(n, e1)
    corner, edge = e1, np.cos(np.radians(30)) * e1 + np.sin(np.radians(30)) * e2
    assert one_ray(hexagon, c + 4 * n, -n) == pytest.approx(4.0, rel=1e-14)
    assert one_ray(hexagon, c + 1.4 * corner + 4 * n, -2 * n) == pytest.approx(2.0, rel=1e-14)
    assert one_ray(hexagon, c + 1.4 * edge + 4 * n, -2 * n) == np.inf
    assert one_ray(hexagon, c + 1.25 * edge + 4 * n, -2 * n) == pytest.approx(2.0, rel=1e-14)


@pytest.mark.parametrize("x, y, inside", [
    (0.5, 0.5, True), (1.5, 0.5, True), (0.5, 1.5, True),    # the three arms of the L
    (1.5, 1.5, False),                                       # the notch
    (2.5, 0.5, False), (-0.5, 0.5, False)])
def test_non_convex_polygon_misses_in_its_notch(x, y, inside):
    """An L-shaped polygon in z = 1: points in the notch are outside."""
    t = one_ray(SHAPES["polygon_L"], (x, y, 4), (0, 0, -1))
    assert t == (3.0 if inside else np.inf)


@pytest.mark.parametrize("x, y, inside", [
    (0.0, 0.0, False),          # the centre: inside the inner pentagon, crossed twice -> even -> out
    (0.1, 0.05, False),         # elsewhere in the inner pentagon
    (0.0, 0.8, True),           # in the top point of the star
    (0.1, 0.8, False),          # beside that point
    (0.0, -0.5, False),         # between the two lower points
    (0.7, 0.25, True)])         # in the upper right point
def test_pentagram_is_filled_by_the_even_odd_rule(x, y, inside):
    """A self-overlapping pentagram: its points are in, its centre pentagon is out (even-odd)."""
    t = one_ray(SHAPES["pentagram"], (x, y, 2), (0, 0, -1))
    assert t == (2.0 if inside else np.inf)


def test_square_analytic_hits():
    """The generic square z = 0, |x|, |y| <= 1 (edges included)."""
    sq = Square()
    assert one_ray(sq, (0.5, -0.5, 3), (0, 0, -1)) == 3.0
    assert one_ray(sq, (1.0, 1.0, 3), (0, 0, -1.5)) == 2.0
    assert one_ray(sq, (1.5, 0, 3), (0, 0, -1)) == np.inf
    assert one_ray(sq, (0, -1.01, 3), (0, 0, -1)) == np.inf
    assert one_ray(sq, (0, 0, 3), (1, 0, 0)) == np.inf


@pytest.mark.parametrize("name, o, d, t", [
    ("plane", (0, 4, 0), (0, -1, 0), 4.0),
    ("triangle_smooth", (0.5, 0.5, 4), (0, 0, -1), 4.0),
    ("polygon_L", (0.5, 0.5, 4), (0, 0, -1), 3.0),
    ("pentagram", (0, 0.8, 4), (0, 0, -1), 4.0),
    ("square", (0, 0, 4), (0, 0, -1), 4.0)])
def test_flat_shapes_t_range_is_open(name, o, d, t):
    """A flat shape's one root t counts only for t_min < t < t_max (arrays or floats)."""
    shape = SHAPES[name]
    assert one_ray(shape, o, d) == t
    assert one_ray(shape, o, d, t_min=t) == np.inf
    assert one_ray(shape, o, d, t_min=t - 1e-9) == t
    assert one_ray(shape, o, d, t_max=t) == np.inf
    assert one_ray(shape, o, d, t_max=np.array([t + 1e-9])) == t
    assert one_ray(shape, o, d, t_max=np.array([t])) == np.inf


def test_a_bow_tie_is_filled_by_the_even_odd_rule(yaml_scene):
    """(0,0) (2,2) (2,0) (0,2): two triangles meeting at (1, 1); Newell's normal is 0 there. Built
    from YAML without complaint, hit inside both loops, missed between them."""
    scene = yaml_scene("""
        camera: {eye: [1, 1, 5], look_at: [1, 1, 0]}
        objects: [{polygon: {vertices: [[0, 0, 1], [2, 2, 1], [2, 0, 1], [0, 2, 1]]}}]
        """)
    bow = scene.objects[0].shape
    for x, y, inside in [(0.3, 1, True), (1.7, 1, True), (1, 0.3, False), (1, 1.7, False), (2.5, 1, False)]:
        assert (one_ray(bow, (x, y, 5), (0, 0, -1)) == 4.0) == inside, (x, y)


# --- batch == one ray at a time ---
def random_rays(shape, n, seed):
    """Origins around the shape, aimed at random points of its (grown) bounds, directions of any length."""
    rng = np.random.default_rng(seed)
    b = shape.bounds()
    lo, hi = (np.full(3, -2.0), np.full(3, 2.0)) if b is None else b
    mid, half = (lo + hi) / 2, (hi - lo) / 2 * 1.3 + 0.05
    target = mid + rng.uniform(-1, 1, (n, 3)) * half
    start = rng.normal(size=(n, 3))
    start = mid + 6 * start / np.linalg.norm(start, axis=1)[:, None] * rng.uniform(0.05, 1, (n, 1))
    d = (target - start) * rng.uniform(0.2, 3, (n, 1))
    return start, d


@pytest.mark.parametrize("name", SHAPES)
def test_batch_equals_one_ray_at_a_time(name):
    """Each ray's t does not depend on the batch it travels in (exactly, bit for bit)."""
    shape = SHAPES[name]
    o, d = random_rays(shape, 300, seed=len(name))
    t_max = np.where(np.arange(300) % 3 == 0, 4.0, np.inf)
    batch, prim = shape.intersect(o, d, 1e-3, t_max)
    assert np.isfinite(batch).sum() > 30, "too few hits to test anything"
    single = [shape.intersect(o[k:k + 1], d[k:k + 1], 1e-3, t_max[k:k + 1]) for k in range(300)]
    np.testing.assert_array_equal(batch, np.concatenate([t for t, _ in single]))
    if prim is not None:
        np.testing.assert_array_equal(prim, np.concatenate([p for _, p in single]))
    assert np.all((batch > 1e-3) & (batch < t_max) | np.isinf(batch))


# --- random transforms: normals and re-intersection ---
def random_transform(rng, mirror: bool) -> tf.Transform:
    s = rng.uniform(0.4, 2.5, 3)
    if mirror:
        s[rng.integers(3)] *= -1                                    # determinant < 0
    t = tf.scale(s).then(tf.rotate(rng.normal(size=3), rng.uniform(0, 360)))
    t = t.then(tf.translate(rng.uniform(-3, 3, 3)))
    assert (np.linalg.det(t.m[:3, :3]) < 0) == mirror
    return t


def scene_of(shape, world_from_object=None) -> Scene:
    obj = SceneObject(1, "", shape, 0, world_from_object)
    return Scene(camera=None, objects=[obj], materials=MaterialTable([Material()]))


TRANSFORMS = [(seed, mirror) for seed in range(3) for mirror in (False, True)]


@pytest.mark.parametrize("seed, mirror", TRANSFORMS)
@pytest.mark.parametrize("from_inside", [False, True])
def test_transformed_sphere_normals_are_unit_and_outward(seed, mirror, from_inside):
    """World normal = normalize(A^-T q) at object-space q: unit, and outward = away from the ellipsoid's centre."""
    rng = np.random.default_rng(seed)
    t = random_transform(rng, mirror)
    s = scene_of(Sphere(), t)
    A, b = t.m[:3, :3], t.m[:3, 3]
    n_rays = 200
    target = b + rng.uniform(-0.3, 0.3, (n_rays, 3))
    u = rng.normal(size=(n_rays, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    start = b + (0.05 * rng.uniform(-1, 1, (n_rays, 3)) if from_inside else 20 * u)
    rays = Rays.from_rows(start, (u if from_inside else target - start))
    hits = find_first_hit(s, rays)
    assert np.all(np.isfinite(hits.t))
    sf = surface(s, rays, hits)
    np.testing.assert_allclose(np.linalg.norm(sf.n.T, axis=1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(sf.entering, not from_inside)
    outward = np.where(sf.entering[:, None], sf.n.T, -sf.n.T)
    assert np.all(np.sum(outward * (sf.p.T - b), axis=1) > 0)
    q = (sf.p.T - b) @ np.linalg.inv(A).T                             # object space
    grad = q @ np.linalg.inv(A)                                     # A^-T q, row by row
    np.testing.assert_allclose(outward, grad / np.linalg.norm(grad, axis=1)[:, None], atol=1e-9)
    assert np.all(np.sum(sf.n.T * rays.d.T, axis=1) < 0)        # N faces the incoming ray


def on_shape(shape, p):
    """Object-space points p moved onto a flat shape's plane (spheres: left as they are)."""
    if isinstance(shape, Sphere):
        return p
    zero = np.zeros(1, dtype=np.int64)
    if isinstance(shape, Triangle):
        p0, n = shape.a, shape.geometric_normal(p[:1], zero)[0]
    else:
        p0 = {Plane: lambda: shape.point, Polygon: lambda: shape.v[0], Square: lambda: np.zeros(3)}[type(shape)]()
        n = shape.normal(p[:1], zero)[0]
    n = n / np.linalg.norm(n)
    return p - np.outer((p - p0) @ n, n)


def aimed_rays(s: Scene, rng, n):
    """Rays from far away at random points of the object's surface region: points of its
    object-space bounds ([-3, 3]^3 for planes) put onto its plane, then into the world."""
    obj = s.objects[0]
    b = obj.shape.bounds()
    lo, hi = (np.full(3, -3.0), np.full(3, 3.0)) if b is None else b
    target = on_shape(obj.shape, rng.uniform(lo, hi, (n, 3)))
    if obj.world_from_object is not None:
        target = obj.world_from_object.point(target)
    u = rng.normal(size=(n, 3))
    start = target + 15 * u / np.linalg.norm(u, axis=1)[:, None]
    return Rays.from_rows(start, target - start)


@pytest.mark.parametrize("name", SHAPES)
def test_normals_under_random_transforms_are_unit_and_face_the_ray(name):
    """Under random affine maps (mirrors too) n, ng are unit, face the ray, and ng = A^-T n_object."""
    rng = np.random.default_rng(7)
    shape = SHAPES[name]
    for seed, mirror in TRANSFORMS:
        t = random_transform(np.random.default_rng(seed + 10), mirror)
        s = scene_of(shape, t)
        rays = aimed_rays(s, rng, 200)
        hits = find_first_hit(s, rays)
        hit = np.isfinite(hits.t)
        assert hit.sum() > 20
        sf = surface(s, rays[hit], hits[hit])
        d = rays.d.T[hit]
        for n in (sf.n.T, sf.ng.T):
            np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
            assert np.all(np.sum(n * d, axis=1) < 0)
        if name in PLANAR and name != "triangle_smooth":
            n_obj = shape.normal(np.zeros((1, 3)), np.zeros(1, dtype=np.int64))[0]
            g = np.linalg.inv(t.m[:3, :3]).T @ n_obj
            g /= np.linalg.norm(g)
            np.testing.assert_allclose(np.abs(sf.ng.T @ g), 1.0, atol=1e-12)


def spawn(s: Scene, p, ng, rng):
    """Random unit directions on ng's side (the side the ray came from), starting where
    rtcli.wavefront.trace starts a mirror ray: p + offset * ng."""
    w = rng.normal(size=p.shape)
    w /= np.linalg.norm(w, axis=1)[:, None]
    w = np.where((np.sum(w * ng, axis=1) < 0)[:, None], -w, w)
    return Rays.from_rows(p + s.offset * ng, w)


@pytest.mark.parametrize("name", SHAPES)
def test_spawned_rays_do_not_reintersect(name):
    """pbrt's Reintersect: rays spawned on a hit's outgoing side never hit the same convex/flat surface."""
    rng = np.random.default_rng(3)
    shape = SHAPES[name]
    for world in [None] + [random_transform(np.random.default_rng(seed + 20), mirror)
                           for seed, mirror in TRANSFORMS]:
        s = scene_of(shape, world)
        rays = aimed_rays(s, rng, 300)
        hits = find_first_hit(s, rays)
        hit = np.isfinite(hits.t)
        sf = surface(s, rays[hit], hits[hit])
        again = find_first_hit(s, spawn(s, sf.p.T, sf.ng.T, rng))
        assert np.all(np.isinf(again.t)), \
            f"re-hit at t = {again.t[np.isfinite(again.t)][:5]} (offset {s.offset:g})"


@pytest.mark.parametrize("seed, mirror", TRANSFORMS)
def test_rays_leaving_inside_a_sphere_go_across_it(seed, mirror):
    """Inside an ellipsoid, rays spawned inward cross to the far side: no re-hit closer than 1e-6 x size."""
    rng = np.random.default_rng(seed)
    s = scene_of(Sphere(), random_transform(rng, mirror))
    b = s.objects[0].world_from_object.m[:3, 3]
    u = rng.normal(size=(300, 3))
    rays = Rays.from_rows(np.broadcast_to(b, (300, 3)).copy(), u)
    hits = find_first_hit(s, rays)
    sf = surface(s, rays, hits)
    assert not sf.entering.any()
    again = find_first_hit(s, spawn(s, sf.p.T, sf.ng.T, rng))
    assert np.all(np.isfinite(again.t))
    assert np.all(again.t > 1e-6 * s.size)
