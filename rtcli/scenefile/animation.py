"""Animation: frames, keyframes, and the scene of each frame (docs/scene-format.md, Animation).

A scene animates with a top-level `animation:` section, the frame rate and either a
frame count or a clock range, and with keyframes in place of the values that may
change: the camera's eye, look_at, up and fov, each light's position and color, the
steps of any transform (translate, scale, rotate's degrees; the camera may have one
too) and a material's coefficients. Frame k (1, 2, ...) shows the time
start + (k - 1) / fps, before the clock range's end, so that a loop whose last key
repeats its first shows no frame twice.

A frame's scene is built by the still-scene builder (build.py) from a copy of the tree
in which each keyframed value is replaced by its value at the frame's time. Only the
mappings and lists on the way to a keyframed value are copied; shapes and textures,
which never change, are built once and shared by every frame (reuse.py). The same time
gives the same values, so a frame's pixels do not depend on which frames were rendered
before it, in which process, or on which machine.
"""

from __future__ import annotations

import bisect
import difflib
import math
from dataclasses import dataclass

import numpy as np

from rtcli.core.scene import Scene
from rtcli.errors import SceneError, Where, plural, shown
from rtcli.scenefile import yamlfile
from rtcli.scenefile.build import build_scene
from rtcli.scenefile.files import reading_scene
from rtcli.scenefile.nodes import MapNode, SeqNode
from rtcli.scenefile.params import Params
from rtcli.scenefile.reuse import Parts, sharing
from rtcli.scenefile.values import describe, finite_numbers, out_of_range

MAX_FRAMES = 100_000
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


@dataclass(frozen=True)
class Clock:
    """When the frames are: frame k at start + (k - 1) / fps, for k = 1 .. frames."""

    frames: int = 1
    fps: float = 24.0
    start: float = 0.0
    end: float = 0.0                        # keys may lie anywhere in [start, end]

    def time(self, k: int) -> float:
        return self.start + (k - 1) / self.fps


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
    if kind == NUMBER or (kind == SCALE and not isinstance(x, list)) or (kind == COEFFICIENT and _number(x)):
        if not _number(x):
            raise SceneError(where, label, f"must be a number, got {describe(x)}")
        if (why := out_of_range(x)) is not None:
            raise SceneError(where, label, why)
        return float(x)
    if kind in (VECTOR, SCALE):
        return finite_numbers(x, where, label, 3, "a vector [x, y, z] of 3 numbers")
    return keys.color_value(name, x, label, where, allow_scalar=kind == COEFFICIENT)


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


# --- finding the keyframed values ---
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


def _clock(p: Params) -> Clock:
    """The `animation:` section: fps (default 24) and exactly one of frames and clock."""
    fps = p.number("fps", 24.0, positive=True)
    if not (p.has("frames") or p.has("clock")):
        p.known("frames", "clock")
        p.check_unused()                                 # a misspelt frames or clock says so
    if p.has("frames") == p.has("clock"):
        raise p.error(None, "give the frame count (frames: 120) or the clock range (clock: [0, 5]), "
                            "not both" if p.has("frames") else "needs frames (a count) or clock ([start, end] in s)")
    if p.has("frames"):
        frames = p.integer("frames", lo=1, hi=MAX_FRAMES)
        p.check_unused()
        return Clock(frames, fps, 0.0, frames / fps)
    start, end = p.numbers("clock", 2, what="a range [start, end] in seconds")
    if not end > start:
        raise p.error("clock", f"the end must come after the start, got [{start:g}, {end:g}]")
    span = (end - start) * fps                  # frames start, start + 1/fps, ... before end
    frames = round(span) if abs(span - round(span)) < 1e-9 * max(span, 1) else math.ceil(span)
    if frames > MAX_FRAMES:
        raise p.error("clock", f"makes {frames:,} frames at {fps:g} fps, more than the {MAX_FRAMES:,} allowed")
    p.check_unused()
    return Clock(frames, fps, start, end)


# --- the animation ---
class Animation:
    """A scene's frames: `scene(k)` builds frame k (1-based); a still has one frame."""

    def __init__(self, docs: list[MapNode]):
        self.docs, self.parts = docs, Parts()
        main = Params(docs[-1], "")
        section = main.optional("animation")
        self.still = section is None
        self.clock = Clock() if section is None else _clock(section)
        self.tracks: dict = {}
        if not self.still:
            finder = _Finder(self.clock)
            for d, doc in enumerate(docs):
                finder.document(doc, d, d == len(docs) - 1)
            self.tracks = finder.found
        self.paths = _trie(self.tracks)

    @property
    def frames(self) -> int:
        return self.clock.frames

    def scene(self, k: int) -> Scene:
        """The scene of frame k, 1..frames."""
        if not 1 <= k <= self.frames:
            raise ValueError(f"frame {k} of {self.frames}")
        return self.scene_at(self.clock.time(k), f"frame {k}, ")

    def scene_at(self, t: float, what: str = "") -> Scene:
        """The scene at time t; an error in a keyframed value says the frame and time."""
        if self.still:
            return build_scene(self.docs)
        self.parts.copies = set()
        docs = [self._copy(doc, self.paths.get(d, {}), t) for d, doc in enumerate(self.docs)]
        try:
            with sharing(self.parts):
                return build_scene(docs)
        except SceneError as e:
            if not any(_related(e, track) for track in self.tracks.values()):
                raise
            raise SceneError(e.where, e.path, f"{e.message} (at {what}time {t:g} s)") from None
        finally:
            self.parts.copies = set()

    def _copy(self, node, paths: dict, t: float):
        """node with the keyframed values under it resolved at time t; copies only what changes."""
        if not paths:
            return node
        new = node.copy()
        self.parts.copies.add(id(new))
        for step, below in paths.items():
            if isinstance(below, Track):
                new.put(step, *below.at(t))
            else:
                new.put(step, self._copy(node[step], below, t))
        return new

    def check_all(self) -> str:
        """Build every frame, and the scene at every keyframe's time (a key between frames is
        checked too); for `rtcli validate`, what the animation is ('' for a still)."""
        if self.still:
            return ""
        for k in range(1, self.frames + 1):
            self.scene(k)
        for t in sorted({t for track in self.tracks.values() for t in track.times}):
            self.scene_at(t)
        c = self.clock
        return (f"; animated: {plural(c.frames, 'frame')} at {c.fps:g} fps ({c.start:g}..{c.end:g} s), "
                f"{plural(len(self.tracks), 'keyframed value')}")


def _trie(tracks: dict) -> dict:
    """{document: {key: {key: ... Track}}}: the paths to the keyframed values, merged."""
    root: dict = {}
    for path, track in tracks.items():
        node = root
        for step in path[:-1]:
            node = node.setdefault(step, {})
        node[path[-1]] = track
    return root


def _related(e: SceneError, track: Track) -> bool:
    """Whether the error is about the keyframed value or a mapping that holds it."""
    if not isinstance(e.where, Where) or e.where.file != track.where.file or not e.path:
        return False
    return e.path == track.label or track.label.startswith((e.path + ".", e.path + "[")) \
        or e.path.startswith((track.label + ".", track.label + "["))


def load_animation(path: str) -> tuple[Animation, Scene, list[str]]:
    """The scene file's animation (one frame for a still), its first frame, and the real paths
    of every file read (see build.load_scene_and_inputs). Later frames read no file: shapes
    and textures are shared."""
    with reading_scene() as inputs:
        animation = Animation(yamlfile.load(path))
        first = animation.scene(1)
    return animation, first, inputs

