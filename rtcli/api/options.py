"""The options of the Python API and the command line, checked alike: their ranges, the engine,
and the image size (width or height alone keeping the scene's aspect ratio)."""

from __future__ import annotations

import os

from rtcli.errors import RtcliError, one_line, shown
from rtcli.kernels import variants
from rtcli.scenefile.files import NUL
from rtcli.scenefile.build import camera_form, check_image_size

RANGES = {"width": (1, 32768), "height": (1, 32768), "samples": (1, 16), "max_depth": (1, 64),
          "workers": (1, 256), "block_size": (1, 1024), "tile": (1, 4096),
          "frame": (1, 100_000),          # as the command line's (frame: scenefile.clock.MAX_FRAMES)
          "tolerance": (0, 255), "max_bad_pixels": (0, None), "max_cluster": (0, None),   # rtcli.diff's gate
          "max_boundary_mismatch": (0, None)}
FRACTIONS = ("max_bad_fraction", "max_boundary_fraction")        # numbers in 0..1
PATHS = ("output", "folder")
CALLBACKS = ("progress", "notes")
OPTIONAL = ("width", "height", "samples", "max_depth", "workers", "frame", "alpha", *PATHS, *CALLBACKS)   # None: not given


def check_options(**options) -> None:
    """RtcliError for an option outside the command line's range (RANGES), engine or flag, a path
    that is not one, or a callback that cannot be called; None is "not given" for OPTIONAL ones."""
    for name, value in options.items():
        if value is None and name in OPTIONAL:
            continue
        if name == "engine":
            if value not in ("auto", "numpy", "compiled"):
                raise RtcliError(f"engine must be auto, numpy or compiled, got {described(value)}")
        elif name in PATHS:
            check_path(name, value)
        elif name in CALLBACKS:
            if not callable(value):
                raise RtcliError(f"{name} must be a function (or None), got {described(value)}")
        elif name in FRACTIONS:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= 1:
                raise RtcliError(f"{name} must be a number in 0..1, got {described(value)}")
        elif name in RANGES:
            lo, hi = RANGES[name]
            if isinstance(value, bool) or not isinstance(value, int) or value < lo or (hi is not None and value > hi):
                span = f"in {lo}..{hi}" if hi is not None else f">= {lo}"
                raise RtcliError(f"{name} must be an integer {span}, got {described(value)}")
        elif not isinstance(value, bool):
            raise RtcliError(f"{name} must be True or False, got {described(value)}")


def check_path(name: str, value) -> str:
    """The path `value` (a str or os.PathLike) as a str; RtcliError naming the argument otherwise,
    or when it holds a NUL byte (no file name does)."""
    path = os.fspath(value) if isinstance(value, os.PathLike) else value
    if not isinstance(path, str):
        raise RtcliError(f"{name} must be a path (a str or os.PathLike), got {described(value)}")
    if "\0" in path:
        raise RtcliError(f"{name} {shown(path)}: {NUL}")
    return path


def described(value) -> str:
    """A value given to the API as a message shows it: its repr, on one line, at most 60 characters."""
    try:
        text = one_line(repr(value))
    except Exception:           # a repr that fails: an int of more digits than Python prints, a broken class
        text = f"a value of type {type(value).__name__}"
    return text if len(text) <= 60 else f"{text[:56]} ..."


def image_size(model, width: int | None, height: int | None,
               names: tuple[str, str] = ("width", "height")) -> tuple[int, int, str | None]:
    """(width, height, note): the scene's size, with width or height alone keeping its aspect
    ratio; the note says when both given stretch a window or screen camera's picture. `names`
    are the options' names in messages."""
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


def check_engine(engine: str) -> None:
    """RtcliError when the compiled engine is asked for without numba."""
    if engine == "compiled" and not variants.ENABLED:
        raise RtcliError("--engine compiled needs numba: pip install -e '.[fast]' in the rtcli folder "
                         "(rtcli is not on the package index)")
