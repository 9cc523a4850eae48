"""Animated images: the frames of an animation as one animated PNG or GIF (Pillow).

An animated PNG keeps every pixel; a GIF has at most 256 colors a frame (Pillow
picks them) and frame delays in hundredths of a second (an APNG's are written in
milliseconds). Delays are whole ticks that alternate so the movie keeps its frame
rate (`delays`). Both loop forever. The
movie is written to a temporary file beside its name and renamed into place, so an
interrupted run leaves no half-written movie; its frames are held in memory until
then (3 bytes a pixel a frame, checked by `check_size`). A frame lasts at most what its
format can say (MAX_DELAY, checked by `check_rate` before any frame is rendered); a GIF
merges identical frames in a row into one, whose delay is checked as the movie is written.
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
MAX_DELAY = {"PNG": 65535, "GIF": 655350}  # ms a frame may last: 65535 / 1000 s (Pillow's APNG), 65535 ticks
KIND = {"PNG": "an animated PNG", "GIF": "a GIF"}


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


def check_rate(path: str, frames: int, fps: float) -> None:
    """Refuse a movie whose frames would last longer than its format can say (a tiny fps)."""
    fmt = movie_format(path)
    if not 1000 / fps <= MAX_DELAY[fmt] or max(delays(frames, fps, TICK[fmt])) > MAX_DELAY[fmt]:
        raise RtcliError(f"-o {shown(path)}: at {fps:g} fps a frame lasts {1 / fps:g} s, longer than the "
                         f"{MAX_DELAY[fmt] / 1000:g} s a frame of {KIND[fmt]} can last; give a higher fps, or "
                         "write the frames to files (frame_%04d.png)")


def _check_runs(path: str, frames: list[np.ndarray], durations: list[int]) -> None:
    """Refuse a GIF whose identical frames in a row (which a GIF holds as one) last too long."""
    first, total = 0, 0
    for k, frame in enumerate(frames):
        if k and not np.array_equal(frame, frames[k - 1]):
            first, total = k, 0
        total += durations[k]
        if total > MAX_DELAY["GIF"]:
            raise RtcliError(f"-o {shown(path)}: frames {first + 1}-{k + 1} are the same picture, which a GIF "
                             f"holds as one frame of {total / 1000:g} s, longer than the "
                             f"{MAX_DELAY['GIF'] / 1000:g} s it can last; write an animated PNG (.apng)")


def write_movie(path: str, frames: list[np.ndarray], fps: float, meta: dict[str, str] | None = None) -> None:
    """Write uint8 (H, W, 3) frames as a movie at `fps` frames a second, looping; `meta`, the
    provenance (rendering/provenance.py), as an APNG's text chunks or a GIF's comment (JSON)."""
    fmt = movie_format(path)
    check_rate(path, len(frames), fps)
    durations = delays(len(frames), fps, TICK[fmt])
    if fmt == "GIF":
        _check_runs(path, frames, durations)
    images = [Image.fromarray(f) for f in frames]
    extra = {}
    if meta and fmt == "PNG":
        extra["pnginfo"] = PngInfo()
        for key, value in meta.items():
            extra["pnginfo"].add_text(key, value)
    elif meta:
        extra["comment"] = provenance.as_json(meta).encode("utf-8")
    write_atomic(path, lambda f: images[0].save(f, format=fmt, save_all=True, append_images=images[1:],
                                                duration=durations, loop=0, **extra))


def delays(frames: int, fps: float, tick: int) -> list[int]:
    """Each frame's delay in ms, a whole number of ticks: frame k ends at the tick nearest k / fps
    seconds, so the delays alternate between the two nearest whole ticks (a GIF at 12 fps: 80, 90,
    80, 80, 90, 80 ... ms for 83.3) and the movie lasts frames / fps to within half a tick."""
    ends = [math.floor(k * 1000 / fps / tick + 0.5) * tick for k in range(frames + 1)]
    return [b - a for a, b in zip(ends, ends[1:])]
