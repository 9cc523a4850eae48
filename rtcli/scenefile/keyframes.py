"""Keyframes: where a scene's values may change, and their value at any time (docs/scene-format.md, Animation).

In place of a value that may change (the camera's eye, look_at, up and fov, each
light's position and color, the steps of any transform: translate, scale, rotate's
degrees; a material's coefficients) a scene may give `{keys: {TIME: VALUE, ...},
ease: ...}`. Each such value is a Track: its keys, checked where they are written as
the value they stand for, and between two keys the value going from one to the
other along the ease. `find_tracks` looks for them at the places the format allows
and nowhere else: keyframes anywhere else reach the still-scene builder, whose
getters refuse them as keyframes (values.describe).
"""

from __future__ import annotations

import bisect
import difflib
import math

import numpy as np

from rtcli.errors import SceneError, plural, shown
from rtcli.scenefile.clock import Clock
from rtcli.scenefile.nodes import MapNode, SeqNode
from rtcli.scenefile.params import Params
from rtcli.scenefile.values import describe, finite_numbers, is_number, out_of_range

EASES = {                                   # s in [0, 1] between two keys -> the share of the way
    "linear": lambda s: s,
    "in": lambda s: s * s,                  # starts slowly
    "out": lambda s: s * (2.0 - s),         # stops slowly
    "in_out": lambda s: s * s * (3.0 - 2.0 * s),     # both: smoothstep
}

# what a keyframed value is: how its keys are read
VECTOR, NUMBER, COLOR, COEFFICIENT, SCALE = "vector", "number", "color", "coefficient", "scale"
WRITTEN = {VECTOR: "a vector [x, y, z]", NUMBER: "a number", COLOR: "a color [r, g, b]",
           COEFFICIENT: "a number or a color [r, g, b]", SCALE: "a number or a vector [x, y, z]"}
CAMERA = {"eye": VECTOR, "look_at": VECTOR, "up": VECTOR, "fov": NUMBER}
LIGHT = {"position": VECTOR, "color": COLOR}
MATERIAL = {"ambient": COEFFICIENT, "diffuse": COEFFICIENT, "specular": COEFFICIENT, "reflection": COEFFICIENT,
            "transmission": COEFFICIENT, "emission": COLOR, "shininess": NUMBER, "ior": NUMBER}
STEP = {"translate": VECTOR, "scale": SCALE}
SOLIDS = ("union", "intersection", "difference")


class Track:
    """The keyframes of one value: times increasing within the clock, values of one kind."""

    def __init__(self, node: MapNode, label: str, kind: str, clock: Clock):
        p = Params(node, label)
        self.label, self.where = label, node.where
        near = difflib.get_close_matches("keys", [str(k) for k in node], n=1) or "ease" in node
        if "keys" not in node and not near:          # a mapping where a plain value was meant
            raise SceneError(node.where, label, f"must be {WRITTEN[kind]}, or keyframes {{keys: {{time: value, "
                             f"...}}}}; got a mapping without keys")
        p.known("keys", "ease")
        p.check_unused()
        self.ease = EASES[p.choice("ease", tuple(EASES), "linear")]
        keys = p.sub("keys")
        if not keys.node:
            raise p.error("keys", "needs at least one keyframe, `time: value`")
        self.times, self.values, self.places = [], [], []
        for k, name in enumerate(keys.node):
            t = self._time(keys, name, clock)
            self.times.append(t)
            self.values.append(_value(keys, name, kind))
            self.places.append(keys.node.places[2 * k + 2])
        if any(np.ndim(v) for v in self.values):                 # numbers among vectors mean [k, k, k]
            self.values = [np.broadcast_to(v, (3,)).astype(float) for v in self.values]

    def _time(self, keys: Params, name: str, clock: Clock) -> float:
        where = keys.node.key_where[name]
        try:
            t = float(name)
        except ValueError:
            raise SceneError(where, keys.key_path(name), "a keyframe's time must be a number of seconds") from None
        if not math.isfinite(t) or not clock.start <= t <= clock.end:
            raise SceneError(where, keys.key_path(name), f"time {t:g} is outside the clock range "
                             f"{clock.start:g}..{clock.end:g} s ({plural(clock.frames, 'frame')} at {clock.fps:g} fps)")
        if self.times and t <= self.times[-1]:
            raise SceneError(where, keys.key_path(name), f"keyframes must be in increasing time: {t:g} "
                             f"follows {self.times[-1]:g}")
        return t

    def at(self, t: float):
        """(value, packed place): a key's own value and place at its time, else the value
        interpolated between the keys around t (held before the first and after the last)
        and the place of the whole keyframed value."""
        k = bisect.bisect_right(self.times, t)
        if k and self.times[k - 1] == t:
            return _plain(self.values[k - 1]), self.places[k - 1]
        if k == 0 or k == len(self.times):
            return _plain(self.values[max(k - 1, 0)]), None
        t0, t1 = self.times[k - 1], self.times[k]
        a, b = self.values[k - 1], self.values[k]
        s = self.ease((t - t0) / (t1 - t0))
        return _plain(a + (b - a) * s), None


def _plain(v):
    """A value as the builder reads it from YAML: a float or a list of floats."""
    return v.tolist() if isinstance(v, np.ndarray) else float(v)


def _value(keys: Params, name: str, kind: str):
    """A keyframe's value, checked as the value it stands for (ranges are checked per frame)."""
    x, where, label = keys.node[name], keys.node.value_where[name], keys.key_path(name)
    if kind == NUMBER or (kind == SCALE and not isinstance(x, list)) or (kind == COEFFICIENT and is_number(x)):
        if not is_number(x):
            raise SceneError(where, label, f"must be a number, got {describe(x)}")
        if (why := out_of_range(x)) is not None:
            raise SceneError(where, label, why)
        return float(x)
    if kind in (VECTOR, SCALE):
        return finite_numbers(x, where, label, 3, "a vector [x, y, z] of 3 numbers")
    return keys.color_value(name, x, label, where, allow_scalar=kind == COEFFICIENT)


def find_tracks(docs: list[MapNode], clock: Clock) -> dict:
    """{(document index, key or item, ...): Track} of the keyframed values of a scene's documents
    (included documents first, the main file last: only its camera may be keyframed)."""
    finder = _Finder(clock)
    for d, doc in enumerate(docs):
        finder.document(doc, d, d == len(docs) - 1)
    return finder.found


class _Finder:
    """Walks the places where values may be keyframed; a mapping there is a Track.

    `found` maps each document's path to a Track: (document index, key or item, ...)."""

    def __init__(self, clock: Clock):
        self.clock, self.found = clock, {}

    def slots(self, node, at: tuple, label: str, kinds: dict) -> None:
        if not isinstance(node, MapNode):
            return
        for key, kind in kinds.items():
            if isinstance(node.get(key), MapNode):
                name = f"{label}.{shown(key)}" if label else shown(key)
                self.found[at + (key,)] = Track(node[key], name, kind, self.clock)

    def document(self, doc: MapNode, d: int, main: bool) -> None:
        if main and isinstance(doc.get("camera"), MapNode):
            self.slots(doc["camera"], (d, "camera"), "camera", CAMERA)
            self.transform(doc["camera"], (d, "camera"), "camera")
        for k, light in _items(doc, "lights"):
            self.slots(light, (d, "lights", k), f"lights[{k}]", LIGHT)
        if isinstance(doc.get("materials"), MapNode):
            for name, m in doc["materials"].items():
                self.slots(m, (d, "materials", name), f"materials.{shown(name)}", MATERIAL)
        self.objects(doc, (d,), "", "objects")

    def objects(self, node, at: tuple, label: str, key: str) -> None:
        for k, o in _items(node, key):
            here, name = at + (key, k), f"{label}.{shown(key)}[{k}]" if label else f"{shown(key)}[{k}]"
            if not isinstance(o, MapNode):
                continue
            if isinstance(o.get("material"), MapNode):
                self.slots(o["material"], here + ("material",), f"{name}.material", MATERIAL)
            self.transform(o, here, name)
            if isinstance(o.get("group"), MapNode):
                self.objects(o["group"], here + ("group",), f"{name}.group", "objects")
            if isinstance(o.get("csg"), MapNode):
                for op in SOLIDS:
                    self.objects(o["csg"], here + ("csg",), f"{name}.csg", op)

    def transform(self, node: MapNode, at: tuple, label: str) -> None:
        for k, step in _items(node, "transform"):
            here, name = at + ("transform", k), f"{label}.transform[{k}]"
            self.slots(step, here, name, STEP)
            if isinstance(step, MapNode) and isinstance(step.get("rotate"), MapNode):
                self.slots(step["rotate"], here + ("rotate",), f"{name}.rotate", {"degrees": NUMBER})


def _items(node, key: str):
    seq = node.get(key) if isinstance(node, MapNode) else None
    return enumerate(seq) if isinstance(seq, SeqNode) else ()
