"""An animation's clock: when its frames are (docs/scene-format.md, Animation).

The `animation:` section gives the frame rate (fps, default 24) and either a frame
count or a clock range in seconds. Frame k (1, 2, ...) shows the time
start + (k - 1) / fps, before the clock range's end, so that a loop whose last key
repeats its first shows no frame twice; a range shorter than one frame has the one
frame at its start. Keyframes may lie anywhere in the range, its end included. The
clock, like every number of a scene, stays within 1e20 s (limits.MAX_MAGNITUDE).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rtcli.scenefile.limits import MAX_MAGNITUDE
from rtcli.scenefile.params import Params

MAX_FRAMES = 100_000


@dataclass(frozen=True)
class Clock:
    """When the frames are: frame k at start + (k - 1) / fps, for k = 1 .. frames."""

    frames: int = 1
    fps: float = 24.0
    start: float = 0.0
    end: float = 0.0                        # keys may lie anywhere in [start, end]

    def time(self, k: int) -> float:
        return self.start + (k - 1) / self.fps


def clock_from(p: Params) -> Clock:
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
        _check_span(p, frames, fps, 0.0)
        p.check_unused()
        return Clock(frames, fps, 0.0, frames / fps)
    start, end = p.numbers("clock", 2, what="a range [start, end] in seconds")
    if not end > start:
        raise p.error("clock", f"the end must come after the start, got [{start:g}, {end:g}]")
    span = (end - start) * fps                  # frames start, start + 1/fps, ... before end
    frames = round(span) if abs(span - round(span)) < 1e-9 * max(span, 1) else math.ceil(span)
    if frames > MAX_FRAMES:
        raise p.error("clock", f"makes {frames:,} frames at {fps:g} fps, more than the {MAX_FRAMES:,} allowed")
    frames = max(frames, 1)                     # shorter than a frame: the one frame at the start
    _check_span(p, frames, fps, start)
    p.check_unused()
    return Clock(frames, fps, start, end)


def _check_span(p: Params, frames: int, fps: float, start: float) -> None:
    """Refuse frame times beyond the numbers a scene may hold (a tiny fps): the last frame's
    time and the clock's end stay within +-MAX_MAGNITUDE s."""
    last = start + (frames - 1) / fps
    if not abs(last) <= MAX_MAGNITUDE or (p.has("frames") and not frames / fps <= MAX_MAGNITUDE):
        raise p.error("fps", f"{frames:,} frames at {fps:g} fps last {frames / fps:g} s, more than the "
                             f"{MAX_MAGNITUDE:g} s a clock may span")
