"""Checks that keep a built scene within its limits (docs/scene-format.md, "Limits").

The number getters of params.py bound each value; these bound what values make
together: the composed transform of an object, the factors of a scale and the
number of objects.
"""

from __future__ import annotations

import numpy as np

from rtcli.core import transform as tf
from rtcli.errors import SceneError
from rtcli.scenefile.limits import MAX_MAGNITUDE, MAX_OBJECTS, RANGE


def bounded(p, t: tf.Transform | None) -> tf.Transform | None:
    """t, if every entry of its matrix and of its inverse is within +-MAX_MAGNITUDE.

    Steps that are each in range can compose to a transform that is not (two scales
    of 1e20), and an inverse that large means the object shrinks beyond what rays
    can be carried into.
    """
    if t is None:
        return t
    if not np.all(np.abs(t.m) <= MAX_MAGNITUDE):
        raise p.error("transform", f"the composed transform is too large: its entries must be {RANGE}")
    if not np.all(np.abs(t.m_inv) <= MAX_MAGNITUDE):
        raise p.error("transform", f"the composed transform shrinks too much: the entries of its inverse "
                                   f"must be {RANGE}")
    return t


def scale_factors(p, s):
    """The factors of `scale:` (one number or three), each 0 or of magnitude at least 1/MAX_MAGNITUDE.

    A factor of 0 is left to the singular-transform check; a tiny non-zero one is
    named for what it is rather than called singular.
    """
    tiny = (np.asarray(s) != 0) & (np.abs(s) < 1 / MAX_MAGNITUDE)
    if np.any(tiny):
        raise p.error("scale", f"a scale factor must be 0 or at least {1 / MAX_MAGNITUDE:g} in magnitude, "
                               f"got {np.asarray(s)[tiny].flat[0]:g}")
    return s


def check_count(objects: list, where, path: str) -> None:
    """Refuse the object at `path` when the scene already holds MAX_OBJECTS."""
    if len(objects) >= MAX_OBJECTS:
        raise SceneError(where, path, f"too many objects: a scene holds at most {MAX_OBJECTS:,}")
