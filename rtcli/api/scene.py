"""The Python API's Scene: a loaded scene, ready to render, with where it came from and the
files it read; its other frames and its overrides (docs/python-api.md).

A Scene wraps the model both engines trace (rtcli.core.scene.Scene) with where it came from
(its name in messages) and the files it read (which outputs never overwrite).
"""

from __future__ import annotations

import os
from collections.abc import Mapping

from rtcli.api.options import RANGES, check_options, image_size
from rtcli.api.pictures import render_scene, signature_scene
from rtcli.api.results import png_bytes
from rtcli.errors import SOURCES, RtcliError, one_line, shown
from rtcli.scenefile.build import summary

Source = str | os.PathLike | Mapping        # what load_scene takes: a path, YAML text or a dict


PREVIEW = 192                         # a scene's inline preview fits in PREVIEW x PREVIEW pixels


class Scene:
    """A loaded scene, ready to render; see rtcli.load_scene."""

    def __init__(self, model, source: str, inputs=(), animation=None, frame: int = 1, overrides=None,
                 warnings=()):
        self.model = model                         # rtcli.core.scene.Scene: what the engines trace
        self.source = source                       # the path, "<string>" or "<dict>"
        self.inputs = tuple(inputs)                # real paths of the files it read
        self.warnings = tuple(one_line(str(w)) for w in warnings)   # `rtcli validate`'s, about frame 1
        self.frame = frame                         # which frame of an animated scene (1 for a still)
        self._animation = animation                # scenefile.animation.Animation, None for a still
        self._overrides = dict(overrides or {})    # load_scene's width, height, samples, max_depth

    @property
    def frames(self) -> int:
        """How many frames the scene has (1 for a still)."""
        return 1 if self._animation is None else self._animation.frames

    @property
    def fps(self) -> float | None:
        """An animated scene's frame rate, None for a still."""
        return None if self._animation is None else self._animation.clock.fps

    def at(self, frame: int) -> Scene:
        """The scene of another frame, with the same overrides (itself for its own frame)."""
        if frame is None:                          # "not given" to check_options, but at() needs one
            raise RtcliError("frame must be an integer in {}..{}, got None".format(*RANGES["frame"]))
        check_options(frame=frame)
        check_frame(self._animation, frame, self.source, "frame")
        if frame == self.frame:
            return self
        other = Scene(self._animation.scene(frame), self.source, self.inputs, self._animation, frame,
                      self._overrides, self.warnings)
        return other.override(**self._overrides)

    def override(self, width: int | None = None, height: int | None = None, samples: int | None = None,
                 max_depth: int | None = None) -> Scene:
        """Set the image size (width or height alone keeps the aspect ratio) and render settings; self."""
        check_options(width=width, height=height, samples=samples, max_depth=max_depth)
        s = self.model.settings
        s.width, s.height, _ = image_size(self.model, width, height)
        s.samples, s.max_depth = samples or s.samples, max_depth or s.max_depth
        self._overrides = {k: v for k, v in dict(width=width, height=height, samples=samples,
                                                 max_depth=max_depth).items() if v}
        return self

    @property
    def width(self) -> int:
        return self.model.settings.width

    @property
    def height(self) -> int:
        return self.model.settings.height

    def render(self, **options):
        """rtcli.render(self, **options)."""
        return render_scene(self, **options)

    def signature(self, **options):
        """rtcli.signature(self, **options)."""
        return signature_scene(self, **options)

    def __repr__(self) -> str:
        frame = f" frame {self.frame} of {self.frames}" if self._animation is not None else ""
        return f"<rtcli.Scene {self.source}{frame}: {summary(self.model)}>"

    def _repr_png_(self) -> bytes:
        """A small preview for Jupyter: one sample per pixel, at most PREVIEW pixels a side."""
        wide = self.width >= self.height
        size = {"width": min(self.width, PREVIEW)} if wide else {"height": min(self.height, PREVIEW)}
        return png_bytes(render_scene(self, samples=1, workers=1, **size))


def check_frame(animation, k: int, source: str, option: str) -> None:
    """RtcliError when frame k is not one of the scene's (`option` names it: "--frame", "frame")."""
    n = 1 if animation is None else animation.frames
    if not 1 <= k <= n:
        name = source if source in SOURCES else shown(source)
        still = animation is None or animation.still
        has = f"{name} is a still (one frame)" if still else f"{name} has {n} frames (1-{n})"
        raise RtcliError(f"{option} {k}: {has}")
