"""Typed, located access to one YAML mapping of a scene (pbrt's ParameterDictionary).

Every getter checks the type, reports errors as `file:line:col: key.path: message`,
and remembers the key as read; `check_unused()` then reports the first key
nobody read, which catches typos such as `raduis:`. An unknown key's message
lists the keys allowed in its mapping and a hint (hints.py); a required key that
is missing while a misspelling of it is given is reported at the misspelling. What
a value may be, and how a wrong one is shown, is values.py's (docs/scene-format.md,
Values).
"""

from __future__ import annotations

import numpy as np

from rtcli.errors import SceneError, Where, shown
from rtcli.scenefile.hints import NOTES_NAMES, misspells, unknown_key_hint
from rtcli.scenefile.limits import MAX_MAGNITUDE
from rtcli.scenefile.nodes import MapNode, SeqNode
from rtcli.scenefile.remarks import note_color
from rtcli.scenefile.yamlbulk import SphereRun
from rtcli.scenefile.values import channel_problem, describe, finite_numbers, is_number, out_of_range

REQUIRED = object()


class Params:
    """The keys of one mapping, read through typed getters."""

    def __init__(self, node: MapNode, path: str):
        if not isinstance(node, MapNode):
            raise TypeError("Params needs a MapNode")
        self.node, self.path = node, path
        self.read: dict[str, None] = {}             # the keys read or allowed, in that order
        for key, where, first in getattr(node, "duplicates", []):
            raise SceneError(where, self.key_path(key), f"duplicate key (first given at line {first.line})")

    # --- locations and errors ---
    @property
    def folder(self) -> str:
        return self.node.folder

    @property
    def where(self) -> Where:
        return self.node.where

    def key_path(self, key: str) -> str:
        return f"{self.path}.{shown(key)}" if self.path else shown(key)

    def error(self, key: str | None, message: str) -> SceneError:
        """An error located at `key`'s value (or at the mapping when key is None)."""
        if key is None:
            return SceneError(self.node.where, self.path, message)
        return SceneError(self.node.value_where.get(key, self.node.where), self.key_path(key), message)

    def has(self, key: str) -> bool:
        return key in self.node

    def known(self, *keys: str) -> None:
        """Mark keys as read: allowed here, but read elsewhere or not at all. Declaring a
        mapping's keys before reading any also keeps them from being taken for
        misspellings of a missing required key."""
        self.read.update(dict.fromkeys(keys))

    def optional(self, key: str) -> "Params | None":
        """The nested mapping at `key` as Params, or None when the key is absent."""
        if key not in self.node:
            self.read[key] = None
            return None
        return self.sub(key)

    def raw(self, key: str, default=REQUIRED):
        """The value as loaded, marked read; a missing required key is an error, reported at
        a key that looks like a misspelling of it when there is one."""
        self.read[key] = None
        if key not in self.node:
            if default is REQUIRED:
                for given in self.node:
                    if given not in self.read and misspells(given, key):
                        raise self.unknown_key(given, key)
                for given in self.node:                  # the notes' name of another key declared here
                    if given not in self.read and isinstance(given, str) and NOTES_NAMES.get(given) in self.read:
                        raise self.unknown_key(given)
                raise SceneError(self.node.where, self.key_path(key), "missing required key")
            return default
        return self.node[key]

    def check_unused(self) -> None:
        for key in self.node:
            if key not in self.read:
                raise self.unknown_key(key)

    def unknown_key(self, key, meant: str | None = None) -> SceneError:
        """'unknown key', with a hint (the notes' name, the key it misspells, or where it
        belongs) and the keys allowed here."""
        allowed = list(self.read)
        hint = unknown_key_hint(key, allowed, meant)
        listed = f"; allowed here: {', '.join(map(shown, allowed))}" if allowed else "; no keys are allowed here"
        return SceneError(self.node.key_where[key], self.key_path(key), f"unknown key{hint}{listed}")

    # --- typed getters ---
    def number(self, key, default=REQUIRED, *, positive=False, non_negative=False) -> float:
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return x
        self._check_number(key, x, positive, non_negative)
        return float(x)

    def _check_number(self, key, x, positive=False, non_negative=False, what="a number"):
        if not is_number(x):
            raise self.error(key, f"must be {what}, got {describe(x)}")
        if (why := out_of_range(x)) is not None:
            raise self.error(key, why)
        if positive and x <= 0:
            raise self.error(key, f"must be > 0, got {x:g}")
        if non_negative and x < 0:
            raise self.error(key, f"must be >= 0, got {x:g}")

    def integer(self, key, default=REQUIRED, lo=None, hi=None) -> int:
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return x
        if not isinstance(x, int) or isinstance(x, bool):
            raise self.error(key, f"must be an integer, got {describe(x)}")
        if (lo is not None and x < lo) or (hi is not None and x > hi):
            raise self.error(key, f"must be in {lo}..{hi}, got {describe(x)}")
        return x

    def boolean(self, key, default=REQUIRED) -> bool:
        x = self.raw(key, default)
        if not isinstance(x, bool):
            raise self.error(key, f"must be true or false, got {describe(x)}")
        return x

    def string(self, key, default=REQUIRED) -> str:
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return x
        if not isinstance(x, str):
            raise self.error(key, f"must be a string, got {describe(x)}")
        return x

    def choice(self, key, options, default=REQUIRED) -> str:
        x = self.string(key, default)
        if x not in options:
            raise self.error(key, f"must be one of {', '.join(options)}, got {describe(x)}")
        return x

    def numbers(self, key, count, default=REQUIRED, what="a vector") -> np.ndarray:
        """A list of exactly `count` finite numbers."""
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return np.array(x, dtype=float)
        return self.numbers_value(key, x, count, what)

    def numbers_value(self, key, x, count, what="a vector", label=None) -> np.ndarray:
        if type(x) is SeqNode and len(x) == count and _plain_numbers(x):
            return np.array(x, dtype=float)
        where = self.node.value_where.get(key, self.node.where)
        return finite_numbers(x, where, label or self.key_path(key), count, f"{what} of {count} numbers")

    def vector(self, key, default=REQUIRED) -> np.ndarray:
        return self.numbers(key, 3, default, "a vector [x, y, z]")

    def vectors(self, key, min_count=1, count=None, default=REQUIRED) -> np.ndarray:
        """A list of vectors, shape (k, 3)."""
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return x
        where = self.node.value_where.get(key, self.node.where)
        if not isinstance(x, list) or len(x) < min_count or (count and len(x) != count):
            need = f"{count}" if count else f"at least {min_count}"
            raise SceneError(where, self.key_path(key), f"must be a list of {need} vectors, got {describe(x)}")
        rows = []
        for k, v in enumerate(x):
            rows.append(self.item_numbers(x, k, v, 3, "a vector [x, y, z]", f"{self.key_path(key)}[{k}]"))
        return np.array(rows, dtype=float).reshape(-1, 3)

    def item_numbers(self, seq, k, v, count, what, label) -> np.ndarray:
        """Item k (value v) of the list seq as `count` finite numbers."""
        where = seq.item_where[k] if isinstance(seq, SeqNode) else self.node.where
        return finite_numbers(v, where, label, count, what)

    def color(self, key, default=REQUIRED) -> np.ndarray:
        """[r, g, b] of non-negative floats, or "#rrggbb"."""
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return np.array(x, dtype=float)
        plain = _plain_channels(x, False, None)
        if plain is not None:
            return plain
        return self.color_value(key, x, self.key_path(key), self.node.value_where.get(key, self.node.where))

    def color_value(self, key, x, label, where, allow_scalar=False, at_most=None) -> np.ndarray:
        if isinstance(x, str):
            if len(x) == 7 and x[0] == "#":
                try:
                    return np.array([int(x[i:i + 2], 16) / 255 for i in (1, 3, 5)])
                except ValueError:
                    pass
            raise SceneError(where, label, f"must be a color [r, g, b] or \"#rrggbb\", got {describe(x)}")
        written = x
        if allow_scalar and is_number(x):
            x = [x, x, x]
        if not isinstance(x, list) or len(x) != 3:
            raise SceneError(where, label, f"must be a color [r, g, b] or \"#rrggbb\", got {describe(x)}")
        for k, v in enumerate(x):
            if (why := channel_problem(v, at_most)) is not None:
                item_where = x.item_where[k] if isinstance(x, SeqNode) else where
                raise SceneError(item_where, f"{label}[{k}]", why)
        note_color(written, where, label)
        return np.array(x, dtype=float)

    def coefficient(self, key, default=REQUIRED, at_most=None) -> np.ndarray:
        """A color or one number k meaning [k, k, k]; each at most `at_most` when given."""
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return np.full(3, float(x)) if is_number(x) else np.broadcast_to(np.array(x, dtype=float), (3,)).copy()
        plain = _plain_channels(x, True, at_most)
        if plain is not None:
            return plain
        return self.color_value(key, x, self.key_path(key), self.node.value_where.get(key, self.node.where),
                                allow_scalar=True, at_most=at_most)

    def sub(self, key, default=REQUIRED) -> Params | None:
        """The nested mapping at `key` as Params."""
        x = self.raw(key, default)
        if x is None and default is None:
            return None
        if not isinstance(x, MapNode):
            raise self.error(key, f"must be a mapping of keys, got {describe(x)}")
        return Params(x, self.key_path(key))

    def items(self, key, default=REQUIRED) -> list[tuple[object, Where, str]]:
        """The list at `key` as (item, where, path) triples."""
        x = self.raw(key, default)
        if x is default and default is not REQUIRED:
            return []
        if not isinstance(x, SeqNode):
            raise self.error(key, f"must be a list, got {describe(x)}")
        out, skip = [], 0                       # a run of spheres read in bulk is one item of many
        for k, v in enumerate(x):
            out.append((v, x.item_where[k], f"{self.key_path(key)}[{k + skip}]"))
            if type(v) is SphereRun:
                skip += len(v) - 1
        return out


def _plain_numbers(x) -> bool:
    """Whether every item of x is an int or a float within +-MAX_MAGNITUDE (what finite_numbers
    accepts), checked without building a label or a location."""
    for v in x:
        if not (type(v) is float or type(v) is int) or not -MAX_MAGNITUDE <= v <= MAX_MAGNITUDE:
            return False
    return True


def _plain_channels(x, allow_scalar: bool, at_most) -> np.ndarray | None:
    """The color of a list of three numbers (or of one number k meaning [k, k, k]) each of
    which channel_problem accepts, at once; None for anything else, which color_value reads
    (and names what is wrong): the common case without building a label or a location.
    Channels above 1 also go the careful way, which notes colors that look like 0-255 values."""
    top = 1.0 if at_most is None else min(at_most, 1.0)
    if allow_scalar and (type(x) is float or type(x) is int):
        return np.full(3, float(x)) if 0 <= x <= top else None
    if type(x) is not SeqNode or len(x) != 3:
        return None
    for v in x:
        if not (type(v) is float or type(v) is int) or not 0 <= v <= top:
            return None
    return np.array(x, dtype=float)


def as_params(item, where: Where, path: str, what: str = "a mapping of keys") -> Params:
    """Params for a list item, or an error if the item is not a mapping."""
    if not isinstance(item, MapNode):
        raise SceneError(where, path, f"must be {what}, got {describe(item)}")
    return Params(item, path)
