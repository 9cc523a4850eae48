"""Params' quick paths (colors, coefficients and vectors of plain numbers read without building
a label or a location) accept exactly what the checked paths accept, with the same numbers, and
leave everything else to them, which name what is wrong at its place."""

import itertools
import math

import numpy as np
import pytest

from rtcli.errors import SceneError
from rtcli.scenefile import params as P
from rtcli.scenefile.values import finite_numbers
from rtcli.scenefile.yamlfile import parse

VALUES = [0, 1, 0.5, -0.0, -1, -0.5, 1e20, 1e21, -1e20, 10**30, True, False, "x", None, math.nan, math.inf, 2, 1.0]


def checked(f):
    """f()'s result, or the message of the SceneError it raises."""
    try:
        return f()
    except SceneError as e:
        return str(e)


def node_of(values):
    """A parsed mapping {k: [values...]} so that its lists are located SeqNodes."""
    text = "{k: [" + ", ".join("null" if v is None else "true" if v is True else "false" if v is False
                               else ".nan" if isinstance(v, float) and math.isnan(v)
                               else ".inf" if v == math.inf else repr(v) for v in values) + "]}"
    return parse(text, "s.yaml")


TRIPLES = list(itertools.product(VALUES, repeat=3))


@pytest.mark.parametrize("allow_scalar, at_most", [(False, None), (True, None), (True, 1)])
def test_quick_colors_agree_with_the_checked_path(allow_scalar, at_most):
    quick_ones = 0
    for triple in TRIPLES:
        node = node_of(triple)
        p, x = P.Params(node, "m"), node["k"]
        slow = checked(lambda: p.color_value("k", x, "m.k", node.value_where["k"], allow_scalar, at_most))
        quick = P._plain_channels(x, allow_scalar, at_most)
        if quick is None:
            continue
        quick_ones += 1
        assert not isinstance(slow, str), (triple, slow)
        np.testing.assert_array_equal(quick, slow)
        assert quick.dtype == slow.dtype and np.array_equal(np.signbit(quick), np.signbit(slow))
    assert quick_ones > 100


@pytest.mark.parametrize("scalar", VALUES)
@pytest.mark.parametrize("at_most", [None, 1])
def test_quick_scalar_coefficients_agree_with_the_checked_path(scalar, at_most):
    p = P.Params(parse("{}", "s.yaml"), "m")
    slow = checked(lambda: p.color_value("k", scalar, "m.k", p.where, True, at_most))
    quick = P._plain_channels(scalar, True, at_most)
    if quick is not None:
        assert not isinstance(slow, str), slow
        np.testing.assert_array_equal(quick, slow)


def test_quick_vectors_agree_with_the_checked_path():
    for triple in TRIPLES:
        node = node_of(triple)
        x = node["k"]
        slow = checked(lambda: finite_numbers(x, node.value_where["k"], "m.k", 3, "a vector"))
        assert P._plain_numbers(x) == (not isinstance(slow, str)), triple
        if P._plain_numbers(x):
            np.testing.assert_array_equal(P.Params(node, "m").numbers_value("k", x, 3), slow)


def test_errors_still_name_the_item():
    p = P.Params(parse("{c: [0.5, -1, 2], v: [1, .nan, 3], r: [1, 2, 3]}", "s.yaml"), "m")
    assert checked(lambda: p.color("c")) == "s.yaml:1:11: m.c[1]: must be a finite number >= 0, got -1"
    assert checked(lambda: p.vector("v")) == "s.yaml:1:26: m.v[1]: must be a finite number between -1e20 and 1e20, got nan"
    assert checked(lambda: p.coefficient("r", at_most=1)) == "s.yaml:1:43: m.r[1]: must be at most 1, got 2"
