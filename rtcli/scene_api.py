"""Scenes for the Python API: loaded from a path, YAML text or a dict, with their overrides.

A Scene wraps the model both engines trace (rtcli.core.scene.Scene) with where it
came from (its name in messages) and the files it read (which outputs never
overwrite). Loading is the command line's: the same checks, the same located
messages (docs/python-api.md).
"""

from __future__ import annotations

import os
from collections.abc import Mapping

from rtcli.errors import SOURCES, RtcliError, one_line, shown
from rtcli.scenefile.limits import MAX_SCENE_BYTES

Source = str | os.PathLike | Mapping        # what load_scene takes: a path, YAML text or a dict
PREVIEW = 192                         # a scene's inline preview fits in PREVIEW x PREVIEW pixels
RANGES = {"width": (1, 32768), "height": (1, 32768), "samples": (1, 16), "max_depth": (1, 64),
          "workers": (1, 256), "block_size": (1, 1024), "tile": (1, 4096),
          "frame": (1, 100_000)}          # as the command line's (frame: scenefile.animation.MAX_FRAMES)


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
        from rtcli.api import render
        return render(self, **options)

    def signature(self, **options):
        """rtcli.signature(self, **options)."""
        from rtcli.api import signature
        return signature(self, **options)

    def __repr__(self) -> str:
        from rtcli.scenefile.build import summary
        frame = f" frame {self.frame} of {self.frames}" if self._animation is not None else ""
        return f"<rtcli.Scene {self.source}{frame}: {summary(self.model)}>"

    def _repr_png_(self) -> bytes:
        """A small preview for Jupyter: one sample per pixel, at most PREVIEW pixels a side."""
        from rtcli.api import render
        from rtcli.results import png_bytes
        wide = self.width >= self.height
        size = {"width": min(self.width, PREVIEW)} if wide else {"height": min(self.height, PREVIEW)}
        return png_bytes(render(self, samples=1, workers=1, **size))


def load(source: Source, folder: str | None = None, frame: int | None = None, option: str = "frame") -> Scene:
    """The Scene of a path, YAML text or a dict (see rtcli.load_scene for which is which), at frame
    `frame` of an animated scene (default 1); `option` names the frame in messages. Its warnings
    (`rtcli validate`'s, about frame 1) are raised as Python warnings (rtcli.RtcliWarning)."""
    from rtcli.inspect import lint
    scene, found = _load(source, folder, frame, option)
    lint.warn(found)
    return scene


def _load(source: Source, folder: str | None, frame: int | None, option: str):
    """The Scene and its warnings (checks.Remark)."""
    from rtcli.inspect import checks
    from rtcli.scenefile import yamlfile
    from rtcli.scenefile.animation import Animation
    from rtcli.scenefile.files import reading_scene
    from rtcli.scenefile.plain import DICT, tree_from_dict
    from rtcli.scenefile.remarks import recording_remarks
    if isinstance(source, Mapping):
        tree, name = tree_from_dict(dict(source), folder or "."), DICT
    elif is_yaml_text(source):
        if len(source) > MAX_SCENE_BYTES:
            raise RtcliError(f"YAML text of {len(source):,} characters: more than a scene file may hold")
        tree, name = yamlfile.parse(source, "<string>", folder or "."), "<string>"
    elif isinstance(source, (str, os.PathLike)):
        if folder is not None:
            raise TypeError("folder= is for YAML text and dicts; a scene file's names are relative to its folder")
        from rtcli.rendering.frames import load as load_file
        path = os.fspath(source)
        loaded = load_file(path, frame, option=option, lint=True)
        return of_loaded(loaded, path), loaded.warnings
    else:
        raise TypeError(f"a scene is a path, YAML text or a dict, not {type(source).__name__}")
    with reading_scene() as inputs, recording_remarks() as remarks:
        animation = Animation(yamlfile.load_tree(tree))
        k = frame or 1
        check_frame(animation, k, name, option)
        first = animation.scene(1)
        model = first if k == 1 else animation.scene(k)
    found = checks.warnings(first, remarks)
    return Scene(model, name, inputs, None if animation.still else animation, k, warnings=found), found


def of_loaded(loaded, path: str) -> Scene:
    """The Scene of a scene file loaded for the command line (rtcli.rendering.frames.Loaded)."""
    animation = None if loaded.animation.still else loaded.animation
    return Scene(loaded.scene, path, loaded.inputs, animation, loaded.frame, warnings=loaded.warnings)


def check_frame(animation, k: int, source: str, option: str) -> None:
    """RtcliError when frame k is not one of the scene's (`option` names it: "--frame", "frame")."""
    n = 1 if animation is None else animation.frames
    if not 1 <= k <= n:
        name = source if source in SOURCES else shown(source)
        still = animation is None or animation.still
        has = f"{name} is a still (one frame)" if still else f"{name} has {n} frames (1-{n})"
        raise RtcliError(f"{option} {k}: {has}")


def is_yaml_text(source: object) -> bool:
    """A str holding a line break, or a flow mapping `{...}`, is YAML text; any other str a path."""
    return isinstance(source, str) and ("\n" in source or source.lstrip().startswith("{"))


def check_options(**options) -> None:
    """RtcliError for an option outside the command line's range (RANGES), engine or flag."""
    for name, value in options.items():
        if value is None:
            continue
        if name == "engine":
            if value not in ("auto", "numpy", "compiled"):
                raise RtcliError(f"engine must be auto, numpy or compiled, got {value!r}")
            continue
        if name not in RANGES:
            if not isinstance(value, bool):
                raise RtcliError(f"{name} must be True or False, got {value!r}")
            continue
        lo, hi = RANGES[name]
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise RtcliError(f"{name} must be an integer in {lo}..{hi}, got {value!r}")


def image_size(model, width: int | None, height: int | None,
               names: tuple[str, str] = ("width", "height")) -> tuple[int, int, str | None]:
    """(width, height, note): the scene's size, with width or height alone keeping its aspect
    ratio; the note says when both given stretch a window or screen camera's picture. `names`
    are the options' names in messages."""
    from rtcli.scenefile.build import camera_form, check_image_size
    sw, sh = model.settings.width, model.settings.height
    w = width or (max(1, round(height * sw / sh)) if height else sw)
    h = height or (max(1, round(width * sh / sw)) if width else sh)
    for given, name, other, value in ((width, names[0], "height", h), (height, names[1], "width", w)):
        if given and value > 32768:
            raise RtcliError(f"{name} {given} makes the {other} {value} (keeping the scene's {sw}x{sh} "
                             "aspect ratio), more than 32768")
    if (why := check_image_size(w, h)) is not None:
        raise RtcliError(why)
    form, note = camera_form(model), None
    if width and height and w * sh != h * sw and form != "fov":
        note = f"the {form} camera keeps its rectangle, so the {sw}x{sh} scene stretches to {w}x{h}"
    return w, h, note
