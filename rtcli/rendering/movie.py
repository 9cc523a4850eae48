"""Animated images: the frames of an animation as one animated PNG or GIF (Pillow).

An animated PNG keeps every pixel; a GIF has at most 256 colors a frame (Pillow
picks them) and frame delays in hundredths of a second (an APNG's are written in
milliseconds). Delays are whole ticks that alternate so the movie keeps its frame
rate (`delays`). Both loop forever. The
movie is written to a temporary file beside its name and renamed into place, so an
interrupted run leaves no half-written movie; its frames are held in memory until
then (3 bytes a pixel a frame, checked by `check_size`).
"""

from __future__ import annotations

import math
import os

import numpy as np
from PIL import Image
from PIL.PngImagePlugin import PngInfo

from rtcli.errors import RtcliError, quoted, shown
from rtcli.rendering import provenance
from rtcli.rendering.writer import write_atomic

FORMATS = {".apng": "PNG", ".gif": "GIF"}
TICK = {"PNG": 1, "GIF": 10}              # ms: the step of a frame's delay as written (Pillow's APNG: 1/1000 s)
MAX_BYTES = 4 << 30                       # frames held in memory for one movie


def movie_format(path: str) -> str:
    """The Pillow format of a movie's name; RtcliError for another extension."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in FORMATS:
        got = f"{quoted(ext)} is not one of" if ext else "no extension; use one of"
        raise RtcliError(f"{shown(path)}: an animation is written as an animated PNG or GIF: {got} "
                         f"{', '.join(FORMATS)}")
    return FORMATS[ext]


def is_movie(path: str | None) -> bool:
    return path is not None and os.path.splitext(path)[1].lower() in FORMATS


def check_size(frames: int, width: int, height: int) -> None:
    """Refuse a movie whose frames would not fit in MAX_BYTES of memory."""
    need = frames * width * height * 3
    if need > MAX_BYTES:
        raise RtcliError(f"a movie of {frames} frames of {width}x{height} holds {need / (1 << 30):.1f} GB of "
                         f"pixels in memory, more than the {MAX_BYTES >> 30} GB allowed; write the frames "
                         "to files instead (-o frame_%04d.png)")


def write_movie(path: str, frames: list[np.ndarray], fps: float, meta: dict[str, str] | None = None) -> None:
    """Write uint8 (H, W, 3) frames as a movie at `fps` frames a second, looping; `meta`, the
    provenance (rendering/provenance.py), as an APNG's text chunks or a GIF's comment (JSON)."""
    fmt = movie_format(path)
    images = [Image.fromarray(f) for f in frames]
    extra = {}
    if meta and fmt == "PNG":
        extra["pnginfo"] = PngInfo()
        for key, value in meta.items():
            extra["pnginfo"].add_text(key, value)
    elif meta:
        extra["comment"] = provenance.as_json(meta).encode("utf-8")
    write_atomic(path, lambda f: images[0].save(f, format=fmt, save_all=True, append_images=images[1:],
                                                duration=delays(len(images), fps, TICK[fmt]), loop=0, **extra))


def delays(frames: int, fps: float, tick: int) -> list[int]:
    """Each frame's delay in ms, a whole number of ticks: frame k ends at the tick nearest k / fps
    seconds, so the delays alternate between the two nearest whole ticks (a GIF at 12 fps: 80, 90,
    80, 80, 90, 80 ... ms for 83.3) and the movie lasts frames / fps to within half a tick."""
    ends = [math.floor(k * 1000 / fps / tick + 0.5) * tick for k in range(frames + 1)]
    return [b - a for a, b in zip(ends, ends[1:])]
