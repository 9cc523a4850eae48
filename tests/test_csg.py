"""CSG on entering/leaving spans: truth tables on rays through known spans, normals, shadows."""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.core.transform import translate
from rtcli.errors import SceneError
from rtcli.shapes.csg import CSG, Child
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
