"""CSG on entering/leaving spans: truth tables on rays through known spans, normals, shadows."""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.core.transform import translate
from rtcli.errors import SceneError
from rtcli.kernels import variants
from rtcli.shapes.base import Shape
from rtcli.shapes.csg import CSG, OPS, Child
from rtcli.shapes.sphere import Sphere

# Two unit spheres on the x axis, centres at x = 0 and x = 1: along the x axis from
# x = -5, sphere A spans t in [4, 6] and sphere B spans [5, 7].
A = Child(Sphere(), None, 1)
B = Child(Sphere(), translate([1, 0, 0]), 2)
O, D = np.array([[-5.0, 0, 0]]), np.array([[1.0, 0, 0]])


def spans_of(op, children=(A, B)):
    t_in, _, t_out, _ = CSG(op, list(children)).spans(O, D)
    return [(a, b) for a, b in zip(t_in[0], t_out[0]) if np.isfinite(a)]


@pytest.mark.parametrize("op, expected", [
    ("union", [(4, 7)]),
    ("intersection", [(5, 6)]),
    ("difference", [(4, 5)]),
])
def test_truth_table_overlapping(op, expected):
    """A op B along a ray through both: union [4,7], intersection [5,6], A - B [4,5]."""
    np.testing.assert_allclose(spans_of(op), expected)


def test_disjoint_union_keeps_two_spans_and_intersection_is_empty():
    """Spheres apart: the union has two spans, the intersection none."""
    far = Child(Sphere(), translate([3, 0, 0]), 2)
    np.testing.assert_allclose(spans_of("union", (A, far)), [(4, 6), (7, 9)])
    assert spans_of("intersection", (A, far)) == []


def test_difference_hole_through_the_middle():
    """A big sphere minus a small one inside it: two spans, hollow in between."""
    big = Child(Sphere(radius=2), None, 1)
    small = Child(Sphere(radius=1), None, 2)
    np.testing.assert_allclose(spans_of("difference", (big, small)), [(3, 4), (6, 7)])


def test_nested_csg():
    """(A u B) - C with C a sphere at x = 0.5 of radius 0.25: the union split in two."""
    inner = Child(CSG("union", [A, B]), None, 1)
    c = Child(Sphere(center=(0.5, 0, 0), radius=0.25), None, 3)
    np.testing.assert_allclose(spans_of("difference", (inner, c)), [(4, 5.25), (5.75, 7)])


def test_intersect_and_normals_of_carved_surface_point_out_of_result():
    """A - B seen from +x: the first hit is B's carved surface, its normal points to +x... out of A - B."""
    csg = CSG("difference", [A, B])
    o, d = np.array([[5.0, 0, 0]]), np.array([[-1.0, 0, 0]])
    t, prim = csg.intersect(o, d, 0.0, np.inf)
    assert t[0] == pytest.approx(5.0)                 # x = 0: where B's surface carves A
    n = csg.normal(o + t[:, None] * d, prim)
    np.testing.assert_allclose(n[0] / np.linalg.norm(n[0]), [1, 0, 0], atol=1e-12)
    assert csg.material_of(prim, 0)[0] == 2           # the carved surface shows B's material


def test_intersect_from_inside_and_t_limits():
    """From inside the union the first hit is the exit; t_max cuts it off."""
    csg = CSG("union", [A, B])
    o = np.array([[0.5, 0, 0]])
    t, _ = csg.intersect(o, D, 0.0, np.inf)
    assert t[0] == pytest.approx(1.5)
    t, _ = csg.intersect(o, D, 0.0, np.array([1.0]))
    assert np.isinf(t[0])


def test_batch_equals_one_at_a_time():
    """Vectorized CSG spans give, ray by ray, exactly what single rays give."""
    rng = np.random.default_rng(3)
    csg = CSG("difference", [A, B, Child(Sphere(center=(0, 0.5, 0), radius=0.6), None, 3)])
    o = rng.normal(size=(200, 3)) * 4
    d = rng.normal(size=(200, 3))
    t, prim = csg.intersect(o, d, 0.0, np.inf)
    for k in range(200):
        t1, p1 = csg.intersect(o[k:k + 1], d[k:k + 1], 0.0, np.inf)
        assert t1[0] == t[k] and (np.isinf(t1[0]) or p1[0] == prim[k])


def test_csg_shadow_sees_the_hole(yaml_scene):
    """A light seen through the hole of a ring (a cylinder-free ring: sphere minus sphere) is not blocked."""
    scene = yaml_scene("""
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
        objects:
          - csg:
              difference:
                - {sphere: {radius: 2}}
                - {sphere: {radius: 1}}
    """)
    from rtcli.wavefront.intersect import occluded
    inside = np.array([[0.0, 0, 0], [0.0, 0, 0]])
    lights = np.array([[0.0, 0, 0.9], [0.0, 0, 3.0]])
    np.testing.assert_array_equal(occluded(scene, inside.T, lights.T), [False, True])   # components (3, n)


def test_csg_of_a_triangle_is_an_error(yaml_scene):
    """Only solids can be csg children."""
    with pytest.raises(SceneError) as e:
        yaml_scene("""
            camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
            objects:
              - csg:
                  union:
                    - {sphere: {}}
                    - {triangle: {vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}}
        """)
    assert str(e.value).endswith("objects[0].csg.union[1]: a csg child must be a solid: "
                                 "sphere, plane, box, cylinder, cone (capped), torus or csg")


def test_touching_solids_have_no_inner_face():
    """Boxes meeting at x = 0: their union is one span, so no face inside it."""
    from rtcli.shapes.box import Box
    left, right = Child(Box((-1, -1, -1), (0, 1, 1)), None, 1), Child(Box((0, -1, -1), (1, 1, 1)), None, 1)
    np.testing.assert_allclose(spans_of("union", (left, right)), [(4, 6)])
    t, _ = CSG("union", [left, right]).intersect(np.array([[-0.5, 0, 0]]), D, np.array([0.0]), np.inf)
    assert t[0] == pytest.approx(1.5)


# --- the span algebra, one ray at a time (the compiled engine's) against the arrays' (the numpy engine's) ---
class Fixed(Shape):
    """A solid whose spans are given: ray i (o[0] = i) has spans[i], (t_in, t_out) pairs; prims 10 k + j."""

    def __init__(self, spans: np.ndarray, k: int):
        self.given, self.k = spans, k
        self.SPANS = spans.shape[1]

    @property
    def solid(self) -> bool:
        return True

    def spans_of(self, o, d):
        rays = o[0].astype(int)
        prims = np.broadcast_to(10 * self.k + np.arange(self.SPANS), (len(rays), self.SPANS))
        return self.given[rays, :, 0], prims, self.given[rays, :, 1], prims + 100


def random_tree(rng, leaves: list, n_rays: int, depth: int = 2):
    """A random CSG over Fixed leaves whose span ends lie on a coarse grid (ties everywhere: equal
    ends, touching spans, empty and zero-length spans, -inf and inf)."""
    children = []
    for _ in range(rng.integers(2, 5)):
        if depth and rng.random() < 0.35:
            children.append(Child(random_tree(rng, leaves, n_rays, depth - 1), None, 0))
            continue
        S = int(rng.integers(1, 3))
        ends = rng.integers(0, 8, (n_rays, S, 2)).astype(float)
        ends[rng.random((n_rays, S, 2)) < 0.05] = -np.inf
        ends[rng.random((n_rays, S, 2)) < 0.05] = np.inf
        ends = np.sort(ends.reshape(n_rays, -1), axis=1).reshape(n_rays, S, 2)     # spans in order
        ends[rng.random((n_rays, S)) < 0.15] = np.inf                             # no span there
        leaf = Fixed(ends, len(leaves))
        leaves.append(leaf)
        children.append(Child(leaf, None, 0))
    return CSG(str(rng.choice(["union", "intersection", "difference"])), children)


def program(csg: CSG, leaves: list) -> list:
    """The postfix program of csg, as rtcli/compiled/pack.py writes it: ("leaf", k) and (op, n)."""
    out = []
    for child in csg.children:
        out += program(child.shape, leaves) if isinstance(child.shape, CSG) else [("leaf", leaves.index(child.shape))]
    return out + [(OPS.index(csg.op), len(csg.children))]


def decode(csg: CSG, prim: int, leaves: list):
    """The numpy engine's prim (child + C x the child's prim, nested) as (leaf, leaf's prim)."""
    child = csg.children[prim % len(csg.children)]
    if isinstance(child.shape, CSG):
        return decode(child.shape, prim // len(csg.children), leaves)
    return leaves.index(child.shape), prim // len(csg.children)


@pytest.mark.parametrize("seed", range(12))
def test_one_ray_at_a_time_the_span_algebra_is_the_numpy_engines(seed):
    """`combine` (plain Python here, compiled in the compiled engine) gives every ray the numpy
    engine's spans, boundary for boundary with the same leaf and surface, and `nearest` its hit."""

    from rtcli.shapes import csg as algebra
    combine, nearest = variants.python(algebra.combine), variants.python(algebra.nearest)
    rng = np.random.default_rng(seed)
    n, leaves = 60, []
    tree = random_tree(rng, leaves, n)
    code = program(tree, leaves)
    o, d = np.array([np.arange(n), np.zeros(n), np.zeros(n)], float), np.ones((3, n))
    t_in, p_in, t_out, p_out = tree.spans_of(o, d)
    t_hit, p_hit = tree.hits(o, d, 2.0, np.inf)
    capacity = sum(leaf.SPANS for leaf in leaves)
    L = len(leaves)
    for i in range(n):
        bt, bid = np.zeros(2 * capacity), np.zeros(2 * capacity, np.int64)
        et, ed, eo, ei = np.zeros(2 * capacity), *np.zeros((3, 2 * capacity), np.int64)
        lists, counts, top, end = np.zeros(2 * L, np.int64), np.zeros(5, np.int64), 0, 0
        for what, arg in code:
            if what == "leaf":
                leaf = leaves[arg]
                for j in range(leaf.SPANS):
                    bt[end:end + 2] = leaf.given[i, j]
                    bid[end:end + 2] = arg + L * (10 * arg + j), arg + L * (10 * arg + j + 100)
                    end += 2
                lists[2 * top:2 * top + 2] = end - 2 * leaf.SPANS, 2 * leaf.SPANS
                top += 1
            else:
                top = combine(what, arg, bt, bid, lists, top, et, ed, eo, ei, counts)
                end = lists[2 * top - 2] + lists[2 * top - 1]
        assert top == 1 and lists[0] == 0
        mine = [(bt[j], divmod(bid[j], L)[::-1]) for j in range(lists[1])]
        theirs = []
        for j in range(t_in.shape[1]):
            if np.isfinite(t_in[i, j]) or np.isfinite(t_out[i, j]) or p_in[i, j] or p_out[i, j]:
                theirs += [(t_in[i, j], decode(tree, p_in[i, j], leaves)),
                           (t_out[i, j], decode(tree, p_out[i, j], leaves))]
        assert [(t, tuple(map(int, p))) for t, p in mine] == [(t, tuple(map(int, p))) for t, p in theirs], f"ray {i}"
        t, ident = nearest(bt, bid, 0, lists[1], 2.0, np.inf)
        assert t == t_hit[i] and (np.isinf(t) or (ident % L, ident // L) == decode(tree, p_hit[i], leaves))


def test_the_numpy_engines_sort_is_precedes_order():
    """CSG.spans_of sorts boundaries with lexsort on (t, -delta); that is `precedes`, stable."""
    from rtcli.shapes.csg import precedes
    rng = np.random.default_rng(1)
    t = rng.integers(0, 4, 40).astype(float)
    t[:3] = -np.inf
    delta = rng.choice([-1, 1], 40)
    order = list(np.lexsort((-delta, t)))
    mine = []                                            # insertion, as combine's sorted_in
    for e in range(40):
        k = len(mine)
        while k > 0 and precedes(t[e], delta[e], t[mine[k - 1]], delta[mine[k - 1]]):
            k -= 1
        mine.insert(k, e)
    assert mine == order


def test_a_cut_flush_with_a_face_cuts():
    """A cube minus a box sharing three of its faces (a notch): no span of length 0 is left where
    the faces coincide, so a ray through the notch misses and one from above lands on its floor,
    the cut's face, with its normal up."""
    from rtcli.shapes.box import Box
    cube, notch = Child(Box((-1, -1, -1), (1, 1, 1)), None, 1), Child(Box((-1, 0, -1), (0, 1, 1)), None, 2)
    csg = CSG("difference", [cube, notch])
    along_z = csg.intersect(np.array([[-0.5, 0.5, 5]]), np.array([[0.0, 0, -1]]), np.array([0.0]), np.inf)
    assert np.isinf(along_z[0][0])
    down = np.array([[-0.5, 5.0, 0]]), np.array([[0.0, -1, 0]])
    t, prim = csg.intersect(*down, np.array([0.0]), np.inf)
    assert t[0] == pytest.approx(5.0) and csg.material_of(prim, 0)[0] == 2
    shading, _ = csg.normals_at(np.array([[-0.5], [0.0], [0.0]]), prim)
    np.testing.assert_allclose(shading[:, 0], [0, 1, 0], atol=1e-12)


def test_solids_that_only_touch_have_an_empty_intersection():
    """Boxes meeting at x = 0 share only a face: their intersection is nothing, not a span of length 0."""
    from rtcli.shapes.box import Box
    left, right = Child(Box((-1, -1, -1), (0, 1, 1)), None, 1), Child(Box((0, -1, -1), (1, 1, 1)), None, 1)
    assert spans_of("intersection", (left, right)) == []
