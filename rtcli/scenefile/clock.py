"""An animation's clock: when its frames are (docs/scene-format.md, Animation).

The `animation:` section gives the frame rate (fps, default 24) and either a frame
count or a clock range in seconds. Frame k (1, 2, ...) shows the time
start + (k - 1) / fps, before the clock range's end, so that a loop whose last key
repeats its first shows no frame twice. Keyframes may lie anywhere in the range,
its end included.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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
