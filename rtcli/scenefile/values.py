"""What a scene's values may be, and how a wrong one is shown (docs/scene-format.md, Values).

A number is an int or a float (not a bool) within +-MAX_MAGNITUDE ("Limits"); a
vector is a list of exactly so many numbers; a color's channel is such a number
>= 0. Each check names the value it refuses as the message shows it (`describe`):
a mapping, a list of 3, 'x', nothing, ... Params' getters (params.py) and the
keyframes (keyframes.py) judge their values with these, so both say the same.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.errors import SceneError, Where, quoted
from rtcli.scenefile.limits import MAX_MAGNITUDE, RANGE
from rtcli.scenefile.nodes import CommentedColor, MapNode, SeqNode


def is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def out_of_range(x) -> str | None:
    """Why the number x is refused (not finite, or beyond +-MAX_MAGNITUDE), or None.

    The limit keeps squares and higher powers of lengths finite (docs/scene-format.md,
    "Limits"); a huge integer is judged without converting it to a float.
    """
    if isinstance(x, int):
        if abs(x) <= MAX_MAGNITUDE:
            return None
        digits = len(str(abs(x))) if x.bit_length() < 10000 else int(x.bit_length() * 0.30103) + 1
        return f"must be {RANGE}, got an integer of {digits} digits"
    if not math.isfinite(x):
        return f"must be a finite number {RANGE}, got {x}"
    if abs(x) > MAX_MAGNITUDE:
        return f"must be {RANGE}, got {x:g}"
    return None


def describe(x) -> str:
    """How a wrong value is shown in a message."""
    if isinstance(x, MapNode):
        return "keyframes, which only the values listed under Animation in docs/scene-format.md take, " \
               "in a scene with an `animation:` section" if "keys" in x else "a mapping"
    if isinstance(x, SeqNode):
        return f"a list of {len(x)}"
    if isinstance(x, str):
        return quoted(x)
    if x is None:
        return "nothing"
    if isinstance(x, CommentedColor):
        return (f"nothing (YAML reads the unquoted {x.text} as a comment: write it in quotes, "
                f"\"{x.text}\")")
    if isinstance(x, bool):
        return str(x).lower()
    if isinstance(x, int) and x.bit_length() > 64:
        return f"an integer of about {int(x.bit_length() * 0.30103) + 1} digits"
    return quoted(x) if not isinstance(x, (int, float)) else repr(x)


def channel_problem(v, at_most=None) -> str | None:
    """Why v is refused as a channel of a color or coefficient, or None."""
    if not is_number(v) or (isinstance(v, float) and not math.isfinite(v)) or v < 0:
        return f"must be a finite number >= 0, got {describe(v)}"
    if (why := out_of_range(v)) is not None:
        return why
    if at_most is not None and v > at_most:
        return f"must be at most {at_most:g}, got {v:g}"
    return None


def finite_numbers(x, where: Where, label: str, count: int, what: str) -> np.ndarray:
    """x as an array if it is a list of exactly `count` numbers within +-MAX_MAGNITUDE, else a located error."""
    if not isinstance(x, list) or len(x) != count:
        raise SceneError(where, label, f"must be {what}, got {describe(x)}")
    for k, v in enumerate(x):
        if not is_number(v) or out_of_range(v) is not None:
            item_where = x.item_where[k] if isinstance(x, SeqNode) else where
            why = out_of_range(v) if is_number(v) else f"must be a finite number, got {describe(v)}"
            raise SceneError(item_where, f"{label}[{k}]", why)
    return np.array(x, dtype=float)
