"""Scene tree -> transforms: an object's or the camera's `transform:` list (docs/scene-format.md, Objects).

The steps (scale, rotate, translate, matrix) compose in the order written, the first
listed applying first; a group's transform applies after each child's own. Every
transform is checked against the scene's limits (guards.bounded).
"""

from __future__ import annotations

import numpy as np

from rtcli.core import transform as tf
from rtcli.scenefile.guards import bounded, scale_factors
from rtcli.scenefile.params import Params, as_params
from rtcli.scenefile.values import describe

STEPS = ("scale", "rotate", "translate", "matrix")          # the kinds of transform step


def transform_from(p: Params) -> tf.Transform | None:
    """The `transform:` list, composed in the order written (first listed applies first)."""
    if not p.has("transform"):
        p.known("transform")
        return None
    total = tf.Transform.identity()
    for item, where, path in p.items("transform"):
        step = as_params(item, where, path, "a mapping with one of: scale, rotate, translate, matrix")
        total = total.then(_one_transform(step))
    return bounded(p, total)


def _one_transform(p: Params) -> tf.Transform:
    keys = list(p.node)
    if len(keys) == 1 and keys[0] not in STEPS:
        p.known(*STEPS)
        p.check_unused()
    if len(keys) != 1:
        raise p.error(None, "each transform step is one of: scale, rotate, translate, matrix")
    kind = keys[0]
    try:
        if kind == "translate":
            return tf.translate(p.vector("translate"))
        if kind == "scale":
            value = p.raw("scale")
            s = p.number("scale") if not isinstance(value, list) else p.vector("scale")
            return tf.scale(scale_factors(p, s))
        if kind == "rotate":
            r = p.sub("rotate")
            r.known("axis", "degrees")
            axis, degrees = r.vector("axis"), r.number("degrees")
            r.check_unused()
            if not np.any(axis):
                raise r.error("axis", "must not be the zero vector")
            return tf.rotate(axis, degrees)
        return tf.Transform.from_matrix(_matrix(p))
    except ValueError as e:
        raise p.error(kind, str(e)) from None


def _matrix(p: Params) -> np.ndarray:
    rows = p.items("matrix")
    if len(rows) not in (3, 4):
        raise p.error("matrix", f"must be 3 or 4 rows of 4 numbers, got {describe(p.node['matrix'])}")
    m = np.eye(4)
    for k, (row, where, path) in enumerate(rows):
        m[k] = p.item_numbers(p.node["matrix"], k, row, 4, "a row of 4 numbers", path)
    if not np.array_equal(m[3], [0, 0, 0, 1]):
        raise p.error("matrix", "the 4th row must be [0, 0, 0, 1] (affine transforms only)")
    return m


def compose(own: tf.Transform | None, parent: tf.Transform | None) -> tf.Transform | None:
    """An object's own transform, then its group's (None: none)."""
    if own is None:
        return parent
    return own if parent is None else own.then(parent)
