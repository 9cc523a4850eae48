"""An animated scene's frames: the scene of each frame (docs/scene-format.md, Animation).

A scene animates with a top-level `animation:` section (its clock, clock.py) and with
keyframes in place of the values that may change (keyframes.py). A frame's scene is
built by the still-scene builder (build.py) from a copy of the tree in which each
keyframed value is replaced by its value at the frame's time. Only the mappings and
lists on the way to a keyframed value are copied; shapes and textures, which never
change, are built once and shared by every frame (reuse.py). The same time gives the
same values, so a frame's pixels do not depend on which frames were rendered before
it, in which process, or on which machine.
"""

from __future__ import annotations

from rtcli.core.scene import Scene
from rtcli.errors import SceneError, Where, plural
from rtcli.scenefile.build import build_scene
from rtcli.scenefile.clock import Clock, clock_from
from rtcli.scenefile.keyframes import Track, find_tracks
from rtcli.scenefile.nodes import MapNode
from rtcli.scenefile.params import Params
from rtcli.scenefile.reuse import Parts, sharing


class Animation:
    """A scene's frames: `scene(k)` builds frame k (1-based); a still has one frame."""

    def __init__(self, docs: list[MapNode]):
        self.docs, self.parts = docs, Parts()
        main = Params(docs[-1], "")
        section = main.optional("animation")
        self.still = section is None
        self.clock = Clock() if section is None else clock_from(section)
        self.tracks = {} if self.still else find_tracks(docs, self.clock)
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
