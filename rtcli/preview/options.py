"""The render options of `rtcli preview`, as `rtcli render` takes them."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Options:
    """The render options of `rtcli preview` (as `rtcli render` takes them)."""

    width: int | None = None
    height: int | None = None
    samples: int | None = None
    max_depth: int | None = None
    engine: str = "auto"
    gamma: bool = False
    bvh: bool = True
    frame: int = 1
    workers: int | None = None     # threads tracing tiles with the compiled engine (default: all cores)
