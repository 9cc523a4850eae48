"""Every kernel's variants agree (Mitsuba's check_vectorization): the numpy variant on arrays,
the compiled one (numba) and the plain-Python one ray at a time (rtcli/kernels/variants.py).

The shape battery runs on every shape of the registry, through each class's examples(), so
a shape added to rtcli/shapes/ is tested here without editing this file. For each: random
rays from around, inside, far away, parallel to the axes and grazing the surface, under no
transform and under random ones (mirrors too). The variants agree bit for bit: kernels use only
exact operations and rtcli's own elementary functions (rtcli/core/elementary.py), never numpy's
or the C library's x ** y, arccos and the like, which differ between CPUs. Misses are inf, hits lie in (t_min, t_max), normals are finite and
non-zero, solids' normals point out, and rays spawned from a hit do not hit it again at t ~ 0.
"""

from __future__ import annotations

from math import atan2 as c_atan2

import numpy as np
import pytest

from rtcli.core import transform as tf
from rtcli.kernels import variants
from rtcli.shapes import SHAPES

EXAMPLES = [(f"{key}{k}", shape) for key, cls in SHAPES.items() for k, shape in enumerate(cls.examples())]
SCALAR = ["python"] + (["compiled"] if variants.ENABLED else [])
PYTHON_RAYS = 200                                      # the plain-Python variant is slow: fewer rays


@pytest.fixture(autouse=True)
def quiet():
    """x / 0 is inf and 0 / 0 NaN in every variant, on purpose: numpy need not warn."""
    with np.errstate(all="ignore"):
        yield


def scalar(kernel, variant: str, **bind):
    return variants.compiled(kernel, **bind) if variant == "compiled" else variants.python(kernel, **bind)


def assert_agree(a, b, what: str):
    """Equal arrays, to the last bit (NaN equal to NaN)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    assert same.all(), f"{what}: {np.count_nonzero(~same)} differ, e.g. {a[~same][:3]} vs {b[~same][:3]}"


# --- the rays ---
def frame(shape):
    b = shape.bounds()
    lo, hi = (np.full(3, -2.0), np.full(3, 2.0)) if b is None else b
    return (lo + hi) / 2, np.maximum((hi - lo) / 2, 0.25)


def rays_for(shape, rng, n=600):
    """Object-space rays as components (3, n), in groups: from around the shape, from inside its
    bounds, from far away, parallel to the axes (zero components), grazing its surface."""
    mid, half = frame(shape)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    target = mid + half * rng.uniform(-1.2, 1.2, (n, 3))
    o = mid + 4 * np.linalg.norm(half) * u
    o[n // 5: 2 * n // 5] = mid + half * rng.uniform(-0.9, 0.9, (n // 5, 3))               # inside
    o[2 * n // 5: 3 * n // 5] = mid + 1e4 * u[2 * n // 5: 3 * n // 5]                      # far away
    d = (target - o) * rng.uniform(0.3, 3, (n, 1))
    axis = np.eye(3)[rng.integers(0, 3, n // 5)] * rng.choice([-1.0, 1.0], (n // 5, 1))
    d[3 * n // 5: 4 * n // 5] = axis                                                         # parallel
    o[3 * n // 5: 4 * n // 5] = mid + half * rng.integers(-2, 3, (n // 5, 3)) / 2            # on planes
    o, d = o.T.copy(), d.T.copy()
    graze = grazing(shape, rng, n - 4 * n // 5)
    o[:, 4 * n // 5:], d[:, 4 * n // 5:] = graze
    return o, d


def grazing(shape, rng, n):
    """Rays skimming the surface: through a hit point, along a tangent, started 2 units back."""
    mid, half = frame(shape)
    o = mid[:, None] + 4 * np.linalg.norm(half) * rng.normal(size=(3, 4 * n))
    d = (mid + half * rng.uniform(-1, 1, (4 * n, 3))).T - o
    t, prim = hits_numpy(shape, o, d, 0.0, np.full(4 * n, np.inf))
    hit = np.flatnonzero(np.isfinite(t))[:n]
    if len(hit) == 0:
        return o[:, :n], d[:, :n]
    p = o[:, hit] + t[hit] * d[:, hit]
    g = np.array(shape.normals_at(p, prim[hit])[1])
    tangent = np.cross(g.T, rng.normal(size=(len(hit), 3))).T
    tangent /= np.linalg.norm(tangent, axis=0)
    out_o, out_d = np.repeat(o[:, :1], n, axis=1), np.repeat(d[:, :1], n, axis=1)
    out_o[:, :len(hit)], out_d[:, :len(hit)] = p - 2 * tangent + 1e-9 * g * rng.choice([-1, 1], len(hit)), tangent
    return out_o, out_d


def limits(rng, n):
    t_min = np.where(rng.random(n) < 0.3, 1e-3, 0.0)
    t_max = np.where(rng.random(n) < 0.3, rng.uniform(0.5, 5, n), np.inf)
    return t_min, t_max


# --- each variant's answers ---
def hits_numpy(shape, o, d, t_min, t_max):
    t, prim = shape.hits(o, d, t_min, t_max)
    return np.array(t, float), np.array(prim)


def hits_scalar(shape, variant, o, d, t_min, t_max):
    """(t, prim) one ray at a time: the shape's hit kernel, or the BVH walk over a mesh's faces."""
    n = o.shape[1]
    if shape.kernels.hit is None:
        from rtcli.compiled.pack import mesh_geometry
        from rtcli.core.bvh import walk
        from rtcli.shapes.triangle import triangle_leaf
        geo, stack = mesh_geometry(shape), np.zeros(shape.bvh.depth + 2, np.int64)
        f = scalar(walk, variant, LEAF=triangle_leaf)
        out = [f(geo, 0, *o[:, i], *d[:, i], t_min[i], t_max[i], 0, stack, 0) for i in range(n)]
        return np.array([r[0] for r in out], float), np.array([r[1] for r in out])
    f = scalar(shape.kernels.hit, variant)
    out = [f(shape.row, shape.pool, *o[:, i], *d[:, i], t_min[i], t_max[i]) for i in range(n)]
    return np.array([r[0] for r in out], float), np.array([r[1] for r in out])


def per_point(kernel, variant, shape, prim, p):
    f = scalar(kernel, variant)
    return np.array([f(shape.row, shape.pool, prim[i], *p[:, i]) for i in range(p.shape[1])], float).T


# --- the battery ---
@pytest.mark.parametrize("variant", SCALAR)
@pytest.mark.parametrize("name, shape", EXAMPLES, ids=[name for name, _ in EXAMPLES])
def test_hits_agree_and_are_in_range(name, shape, variant):
    rng = np.random.default_rng(len(name))
    o, d = rays_for(shape, rng)
    t_min, t_max = limits(rng, o.shape[1])
    t, prim = hits_numpy(shape, o, d, t_min, t_max)
    keep = slice(None) if variant == "compiled" else slice(0, PYTHON_RAYS)
    t2, prim2 = hits_scalar(shape, variant, o[:, keep], d[:, keep], t_min[keep], t_max[keep])
    graze = np.arange(len(t2)) >= 4 * o.shape[1] // 5
    assert_agree(t[keep][~graze], t2[~graze], f"{name} t")
    assert_agree(t[keep][graze], t2[graze], f"{name} t, grazing")
    hit = np.flatnonzero(np.isfinite(t[keep]) & np.isfinite(t2))
    other = hit[prim[keep][hit] != prim2[hit]]
    if shape.kernels.hit is None:              # a tie between a mesh's faces (an edge) may go either way
        from rtcli.shapes.triangle import triangle_t
        other = other[triangle_t(shape.pool, prim2[other], *o[:, other], *d[:, other]) != t[other]]
    assert len(other) == 0, f"{name}: other prims at rays {other[:5]}"
    finite = np.isfinite(t)
    assert 0.05 < finite.mean() < 0.95, "the rays must both hit and miss"
    assert np.all((t[finite] > t_min[finite]) & (t[finite] < t_max[finite]))


@pytest.mark.parametrize("name, shape", EXAMPLES, ids=[name for name, _ in EXAMPLES])
def test_rays_pointing_away_miss(name, shape):
    """From outside the bounding sphere, heading away from it: inf. An unbounded shape (a plane):
    a line that meets it ahead of its start misses it behind."""
    rng = np.random.default_rng(5)
    mid, half = frame(shape)
    u = rng.normal(size=(3, 500))
    u /= np.linalg.norm(u, axis=0)
    o, d = mid[:, None] + 3 * np.linalg.norm(half) * u, u * rng.uniform(0.1, 10, 500)
    if shape.bounds() is None:
        d = rng.normal(size=(3, 500))
        ahead = np.isfinite(hits_numpy(shape, o, d, 0.0, np.full(500, np.inf))[0])
        assert ahead.sum() > 100
        o, d = o[:, ahead], -d[:, ahead]
    t, _ = hits_numpy(shape, o, d, 0.0, np.full(o.shape[1], np.inf))
    assert np.all(np.isinf(t))


@pytest.mark.parametrize("variant", SCALAR)
@pytest.mark.parametrize("name, shape", EXAMPLES, ids=[name for name, _ in EXAMPLES])
def test_normals_and_uv_agree_at_hits(name, shape, variant):
    rng = np.random.default_rng(len(name) + 1)
    o, d = rays_for(shape, rng)
    t, prim = hits_numpy(shape, o, d, 0.0, np.full(o.shape[1], np.inf))
    hit = np.flatnonzero(np.isfinite(t))
    hit = hit if variant == "compiled" else hit[:PYTHON_RAYS]
    p, prim = o[:, hit] + t[hit] * d[:, hit], prim[hit]
    n, g = shape.normals_at(p, prim)
    both = per_point(shape.kernels.normals, variant, shape, prim, p)
    assert_agree(np.concatenate([n, g]), both, f"{name} normals")
    u, v = shape.uv_at(p, prim)
    assert_agree(np.array([u, v]), per_point(shape.kernels.uv, variant, shape, prim, p), f"{name} uv")
    for normal in (n, g):
        length = np.linalg.norm(normal, axis=0)
        assert np.all(np.isfinite(length) & (length > 0))


@pytest.mark.parametrize("variant", SCALAR)
@pytest.mark.parametrize("name, shape", [(n, s) for n, s in EXAMPLES if s.solid],
                         ids=[n for n, s in EXAMPLES if s.solid])
def test_spans_agree_and_normals_point_out(name, shape, variant):
    """A solid's intervals: the same in every variant; entering the first one, the ray runs against
    the outward normal, leaving the last one, with it (rays aimed at random points: a cone's apex
    or a spindle torus's crossing points have a normal by convention, not a tangent plane)."""
    rng = np.random.default_rng(len(name) + 2)
    o, d = rays_for(shape, rng)
    keep = slice(None) if variant == "compiled" else slice(0, PYTHON_RAYS)
    parts = shape.kernels.spans(shape.row, shape.pool, *o, *d)
    f = scalar(shape.kernels.spans, variant)
    one = np.array([f(shape.row, shape.pool, *o[:, i], *d[:, i]) for i in range(o.shape[1])[keep]], float).T
    graze = np.arange(one.shape[1]) >= 4 * o.shape[1] // 5
    for k, part in enumerate(parts):
        whole = np.broadcast_to(part, o.shape[1:])[keep]
        assert_agree(whole[~graze], one[k][~graze], f"{name} spans[{k}]")
        assert_agree(whole[graze], one[k][graze], f"{name} spans[{k}], grazing")
    aimed = slice(0, o.shape[1] // 5)
    t_in, p_in, t_out, p_out = shape.spans_of(o[:, aimed], d[:, aimed])
    o, d = o[:, aimed], d[:, aimed]
    rows = np.arange(o.shape[1])
    last = np.argmax(np.where(np.isfinite(t_out), t_out, -np.inf), axis=1)
    for t, prim, sign in ((t_in[:, 0], p_in[:, 0], -1), (t_out[rows, last], p_out[rows, last], 1)):
        ok = np.isfinite(t) & (t_out[rows, last] > t_in[:, 0])              # not a touch at one point
        _, g = shape.normals_at(o[:, ok] + t[ok] * d[:, ok], prim[ok])
        cos = np.sum(g * d[:, ok], axis=0) / np.linalg.norm(g, axis=0) / np.linalg.norm(d[:, ok], axis=0)
        assert np.all(sign * cos[np.abs(cos) > 1e-6] > 0), f"{name}: a normal points in"


@pytest.mark.parametrize("name, shape", EXAMPLES, ids=[name for name, _ in EXAMPLES])
def test_rays_launched_from_a_hit_do_not_hit_it_again(name, shape):
    """pbrt's Reintersect: from a hit stepped 1e-6 x size off the surface, to the side the ray came
    from, new rays into that side find no hit closer than 1e-4 x size (rays aimed at random points,
    not along the axes: a hit on a box's edge lies on two faces)."""
    rng = np.random.default_rng(len(name) + 3)
    o, d = rays_for(shape, rng)
    o, d = o[:, :3 * o.shape[1] // 5], d[:, :3 * d.shape[1] // 5]
    t, prim = hits_numpy(shape, o, d, 0.0, np.full(o.shape[1], np.inf))
    hit = np.isfinite(t)
    p = o[:, hit] + t[hit] * d[:, hit]
    g = shape.normals_at(p, prim[hit])[1]
    g = g / np.linalg.norm(g, axis=0) * -np.sign(np.sum(g * d[:, hit], axis=0))       # facing the ray
    size = 2 * np.linalg.norm(frame(shape)[1])
    w = rng.normal(size=p.shape)
    w = np.where(np.sum(w * g, axis=0) < 0, -w, w)
    again, _ = hits_numpy(shape, p + 1e-6 * size * g, w, 0.0, np.full(p.shape[1], np.inf))
    assert np.all(again > 1e-4 * size), f"re-hit at t = {again[again <= 1e-4 * size][:4]}"


# --- transformed: world rays into object space, normals back, in every variant ---
def random_transform(rng, mirror: bool) -> tf.Transform:
    s = rng.uniform(0.4, 2.5, 3) * np.where(np.arange(3) == rng.integers(3), -1 if mirror else 1, 1)
    return tf.scale(s).then(tf.rotate(rng.normal(size=3), rng.uniform(0, 360))).then(tf.translate(rng.normal(size=3)))


@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize("variant", SCALAR)
@pytest.mark.parametrize("name, shape", EXAMPLES, ids=[name for name, _ in EXAMPLES])
def test_transformed_hits_and_normals_agree(name, shape, variant, mirror):
    rng = np.random.default_rng(len(name) + 4 + mirror)
    m = random_transform(rng, mirror).packed
    o, d = rays_for(shape, rng, 300)
    o, d = np.array(tf.affine(m, tf.WORLD, *o)), np.array(tf.linear(m, tf.WORLD, *d))     # world space
    into, back = scalar(tf.ray_to_object, variant), scalar(tf.normal_to_world, variant)
    keep = slice(None) if variant == "compiled" else slice(0, PYTHON_RAYS // 2)
    local = np.array(tf.ray_to_object(m, 0, *o, *d))
    one = np.array([into(m, 0, *o[:, i], *d[:, i]) for i in range(o.shape[1])[keep]]).T
    assert_agree(local[:, keep], one, f"{name} ray_to_object")
    t, prim = hits_numpy(shape, local[:3], local[3:], 0.0, np.full(o.shape[1], np.inf))
    hit = np.flatnonzero(np.isfinite(t[keep]))
    n, _ = shape.normals_at(local[:3, hit] + t[hit] * local[3:, hit], prim[hit])
    world = np.array(tf.normal_to_world(m, 0, *n))
    assert_agree(world, np.array([back(m, 0, *n[:, i]) for i in range(len(hit))]).T, f"{name} A^-T n")


# --- the core's kernels ---
def core_cases():
    """(name, kernel, numpy arguments, per-ray arguments (i) -> tuple, count)."""
    from rtcli.core import camera, dielectric, jitter, lights, shading, textures, vec
    rng = np.random.default_rng(9)
    n = 400
    stacks, counts = rng.choice([1.0, 1.33, 1.5, 2.4], (4, n)), rng.integers(0, 5, n)
    a, b = rng.normal(size=(3, n)), rng.normal(size=(3, n))
    unit_b = b / np.linalg.norm(b, axis=0)
    eta = rng.choice([1 / 1.5, 1.5, 1.33], n)
    light = lights.PointLight(np.array([1.0, 4, 2]), np.array([0.9, 0.8, 0.7]), np.array([1.0, 0.1, 0.02]),
                              np.array([0.0, -1, 0]), 0.7, 3.0, np.array([1.0, 0, 0]), np.array([0, 0, 0.5]), 3).row
    cam = camera.from_fov([0, 1, 5], [0, 0, 0], [0, 1, 0], 40, 64, 48).row
    checker = textures.texture_row(textures.Checker(np.array([1.0, 0.5, 0]), np.array([0, 0.2, 1.0]), 0.3))
    texels = rng.integers(0, 256, (35, 3), dtype=np.uint8)
    image = textures.texture_row(textures.ImageTexture(texels.reshape(7, 5, 3), True))
    clamped = textures.texture_row(textures.ImageTexture(texels.reshape(7, 5, 3), False))
    ij = rng.integers(0, 4000, (2, n))
    cells = rng.integers(0, 16, n)
    uv = rng.uniform(-2, 3, (2, n))
    cases = [
        ("reflect", vec.reflect, (*a, *unit_b)),
        ("refract", vec.refract, (*(-unit_b + 0.5 * a / np.linalg.norm(a, axis=0)), *unit_b, eta)),
        ("unit", vec.unit, tuple(a)),
        ("cross", vec.cross, (*a, *b)),
        ("primary_ray", camera.primary_ray, (cam, rng.uniform(0, 64, n), rng.uniform(0, 48, n), 64, 48)),
        ("hash_pixel", jitter.hash_pixel, (ij[0], ij[1], cells, cells % 2)),
        ("hash_point", jitter.hash_point, (*a, cells, cells % 2)),
        ("sample_point", lights.sample_point, (light, cells % 9, *a)),
        ("toward", lights.toward, (*(a + 5), *a)),
        ("weight", lights.weight, (light, np.abs(a[0]) + 0.5, *unit_b, 9)),
        ("checker", textures.checker, (checker, *a)),
        ("image", textures.image, (image, texels, *uv)),
        ("image clamped", textures.image, (clamped, texels, *uv)),
        ("specular_cos phong", shading.specular_cos, (False, *unit_b, *(a / np.linalg.norm(a, axis=0)),
                                                      *(-unit_b), a[0], b[0])),
        ("specular_cos blinn", shading.specular_cos, (True, *unit_b, *(a / np.linalg.norm(a, axis=0)),
                                                      *(-unit_b), a[0], b[0])),
        ("facing", shading.facing, (*a, *unit_b, *(unit_b + 0.3 * a))),
        ("fresnel", dielectric.fresnel, (rng.uniform(0, 1, n), eta)),
        ("indices", dielectric.indices, (stacks, counts, 1.1, rng.choice([1.0, 1.33, 1.5, 2.4], n), cells % 2 == 0)),
    ]
    return cases, n


CORE, N_CORE = core_cases()


@pytest.mark.parametrize("variant", SCALAR)
@pytest.mark.parametrize("name, kernel, args", CORE, ids=[c[0] for c in CORE])
def test_core_kernels_agree(name, kernel, args, variant):
    with np.errstate(all="ignore"):
        whole = kernel(*args)
    whole = whole if isinstance(whole, tuple) else (whole,)
    f = scalar(kernel, variant)
    count = N_CORE if variant == "compiled" else PYTHON_RAYS

    def at(x, i):
        if isinstance(x, np.ndarray) and x.shape[-1:] == (N_CORE,):
            return x[i] if x.ndim == 1 else x[:, i]            # a ray's value, or its column of a stack
        return x
    ones = [f(*(at(x, i) for x in args)) for i in range(count)]
    ones = [r if isinstance(r, tuple) else (r,) for r in ones]
    for k, part in enumerate(whole):
        assert_agree(np.broadcast_to(part, (N_CORE,))[:count].astype(float), [float(r[k]) for r in ones],
                     f"{name}[{k}]")


@pytest.mark.parametrize("variant", SCALAR)
def test_media_stacks_agree(variant):
    """refracted_media fills the refracted rays' stacks: (D, n) columns at once, or one (D,) row."""
    from rtcli.core.dielectric import refracted_media
    rng = np.random.default_rng(6)
    n = 300
    ior, count = rng.choice([1.0, 1.33, 1.5], (5, n)), rng.integers(0, 5, n)
    ior_m, entering = rng.choice([1.0, 1.33, 1.5], n), rng.random(n) < 0.5
    count = np.where(entering, np.minimum(count, 4), count)
    whole = np.zeros((5, n))
    counts = refracted_media(ior, count, ior_m, entering, whole)
    f = scalar(refracted_media, variant)
    for i in range(n if variant == "compiled" else PYTHON_RAYS):
        row = np.zeros(5)
        assert f(ior[:, i].copy(), int(count[i]), ior_m[i], bool(entering[i]), row) == counts[i]
        np.testing.assert_array_equal(row[:counts[i]], whole[:counts[i], i])


def test_shading_kernels_agree_on_material_tables(yaml_scene):
    """ambient, diffuse and specular read the MaterialTable (numpy) or the compiled engine's copy of it."""
    scene = yaml_scene("""
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
        materials:
          a: {diffuse: [0.7, 0.2, 0.1], specular: 0.6, shininess: 37.5, emission: [0.1, 0, 0.2]}
          b: {preset: brass}
        objects: [{sphere: {}, material: a}, {sphere: {center: [2, 0, 0]}, material: b}]
        """)
    from rtcli.core import shading
    table, rng = scene.materials, np.random.default_rng(4)
    m, T, w, cos = rng.integers(0, len(table), 300), rng.uniform(0, 1, (3, 300)), rng.uniform(0, 2, 300), \
        rng.uniform(-1, 1, 300)
    I, Ia = np.array([0.9, 0.8, 0.5]), np.array([0.1, 0.2, 0.3])
    cases = [(shading.ambient, (m, Ia, *T)), (shading.diffuse, (m, I, w, cos, *T)), (shading.specular, (m, I, w, cos))]
    looks = None
    if variants.ENABLED:
        from rtcli.compiled.pack import looks as pack_looks
        looks = pack_looks(scene)
    for kernel, args in cases:
        whole = np.array(kernel(table, *args))
        for variant, mats in [("python", table)] + ([("compiled", looks)] if looks is not None else []):
            f = scalar(kernel, variant)
            one = np.array([f(mats, *(x[i] if isinstance(x, np.ndarray) and x.shape == (300,) else
                                      (x[:, i] if isinstance(x, np.ndarray) and x.shape == (3, 300) else x)
                                      for x in args)) for i in range(300)]).T
            assert_agree(whole, one, f"{kernel.__name__} {variant}")


def all_kernels() -> list:
    """Every kernel defined in rtcli's modules."""
    import importlib
    import pkgutil

    import rtcli
    found = []
    for info in pkgutil.walk_packages(rtcli.__path__, "rtcli."):
        module = importlib.import_module(info.name)
        found += [f for f in vars(module).values()
                  if variants.is_kernel(f) and getattr(f, "__module__", None) == info.name]
    return found


def test_kernels_take_no_math_from_numpy_or_the_c_library():
    """numpy's x ** y, arccos, arcsin, arctan2, cbrt, tan, exp and log come from SVML on AVX-512 CPUs
    and differ from the C library's in the last bit; every kernel uses rtcli's own instead."""
    kernels = all_kernels()
    assert len(kernels) > 100
    assert {f.__name__: variants.foreign_math(f) for f in kernels if variants.foreign_math(f)} == {}


@variants.kernel
def powered(x):
    return x ** 2.5


@variants.kernel
def through_numpy(x):
    return np.exp(x) + np.sqrt(x)


@variants.kernel
def calls_both(x):
    return powered(x) + through_numpy(x)


@variants.kernel
def by_name(y, x):
    return c_atan2(y, x)


def test_foreign_math_is_found_through_calls():
    """The guard above can fail: x ** y, np.exp and a C-library function imported by name are found,
    in a kernel or in one it calls; np.sqrt (exact) is not."""
    assert variants.foreign_math(powered) == {"**"}
    assert variants.foreign_math(through_numpy) == {"numpy.exp"}
    assert variants.foreign_math(calls_both) == {"**", "numpy.exp"}
    assert variants.foreign_math(by_name) == {"c_atan2"}
