"""The options of the Python API and the command line, checked alike: their ranges, the engine,
and the image size (width or height alone keeping the scene's aspect ratio)."""

from __future__ import annotations

from rtcli.kernels import variants
from rtcli.errors import RtcliError
from rtcli.scenefile.build import camera_form, check_image_size

RANGES = {"width": (1, 32768), "height": (1, 32768), "samples": (1, 16), "max_depth": (1, 64),
          "workers": (1, 256), "block_size": (1, 1024), "tile": (1, 4096),
          "frame": (1, 100_000)}          # as the command line's (frame: scenefile.clock.MAX_FRAMES)


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
