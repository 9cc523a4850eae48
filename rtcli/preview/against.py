"""`rtcli preview --against GOLDEN.png`: each finished render compared with a golden image, as
`rtcli compare` does (rtcli.diff: the golden gate, its heat map, and NVIDIA FLIP's error map
when flip-evaluator is installed)."""

from __future__ import annotations

import numpy as np

from rtcli.api.results import png_bytes
from rtcli.compare.difference import diff
from rtcli.compare.images import read_png
from rtcli.errors import RtcliError, shown


def flip_installed() -> bool:
    try:
        import flip_evaluator  # noqa: F401
    except ImportError:
        return False
    return True


class Golden:
    """The golden image, and the pictures of the last comparison with it (PNG bytes)."""

    def __init__(self, path: str):
        self.path, self.pixels = path, read_png(path)
        if self.pixels.ndim != 3:
            raise RtcliError(f"{shown(path)}: an id map (16-bit gray); --against takes an RGB image")
        self.flip = flip_installed()
        self.pictures = {"golden": png_bytes(self.pixels)}

    def about(self) -> dict:
        """What a page is told of the golden image: its name and size, and whether FLIP is there."""
        h, w = self.pixels.shape[:2]
        return {"name": shown(self.path), "width": w, "height": h, "flip": self.flip}

    def compare(self, render: int, image: np.ndarray) -> dict:
        """Compare a finished render's picture with the golden image: the message for the pages;
        its heat map and FLIP map (for the same size) kept as pictures."""
        same = image.shape == self.pixels.shape
        d = diff(image, self.pixels, flip=self.flip and same)
        pictures = {"golden": self.pictures["golden"]}
        if d.heat_map is not None:
            pictures["diff"] = png_bytes(np.asarray(d.heat_map))
        if d.flip_map is not None:
            pictures["flip"] = png_bytes(np.asarray(d.flip_map))
        self.pictures = pictures
        return {"type": "compare", "render": render, "summary": d.summary, "ok": d.ok,
                "diff": "diff" in pictures, "flip": "flip" in pictures}
