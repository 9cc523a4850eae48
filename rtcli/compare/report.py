"""The HTML report of `rtcli compare ACTUAL_DIR EXPECTED_DIR --report DIR`, one row per pair, worst first.

DIR/index.html shows for each pair the actual and expected images, the heat map of
their difference (compare.heat_map; for id maps, the pixels whose ids differ; float images
shown clamped, their heat map in units of the float tolerance), NVIDIA FLIP's error map
when flip-evaluator is installed (8-bit pairs), the summary numbers, and the notes on how
the two images were made when that differs. The
pictures are PNGs in DIR/images/, so the folder is the whole report (CI uploads it as
it is); the page loads nothing else and needs no script to read (one small script
marks a picture that failed to load). It is built in a temporary folder beside DIR
and renamed into place: DIR may be new, empty or an earlier rtcli report (which has
the file MARKER), never anything else, nor inside or around a compared folder.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import os
import shutil
import tempfile

import numpy as np
from PIL import Image

from rtcli.compare import floats
from rtcli.compare import images as gate
from rtcli.compare.folders import Pair, comparable
from rtcli.compare.report_html import page
from rtcli.core.display import signature_colors
from rtcli.errors import RtcliError, shown
from rtcli.rendering.writer import current_umask

MARKER = ".rtcli-report"


def check_report_dir(path: str, folders: list[str]) -> None:
    """RtcliError unless `path` may become the report: see the module docstring."""
    real = os.path.realpath(path)
    for folder in folders:
        inside = os.path.realpath(folder)
        if os.path.commonpath([real, inside]) in (real, inside):
            raise RtcliError(f"{shown(path)}: the report folder must be outside the compared folders "
                             f"(and not hold them): {shown(folder)}")
    if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise RtcliError(f"{shown(path)}: the folder it would be made in does not exist")
    if os.path.lexists(path):
        if not os.path.isdir(path) or os.path.islink(path):
            raise RtcliError(f"{shown(path)}: exists and is not a folder; it will not be replaced")
        if os.listdir(path) and not os.path.isfile(os.path.join(path, MARKER)):
            raise RtcliError(f"{shown(path)}: a folder that is neither empty nor an rtcli report; it will not "
                             "be replaced (choose a new or empty folder)")


class Report:
    """A report being built: keep() writes each pair's pictures, finish() the page, place() moves it in."""

    def __init__(self, path: str, tolerance: int, titles: tuple[str, str], float_tolerance: float = 0.01):
        self.path, self.tolerance, self.titles = path, tolerance, titles
        self.float_tolerance = float_tolerance
        self.flip = importlib.util.find_spec("flip_evaluator") is not None
        self.tmp = tempfile.mkdtemp(prefix=".rtcli-report-", dir=os.path.dirname(os.path.abspath(path)))
        os.mkdir(os.path.join(self.tmp, "images"))
        self.pictures: dict[str, dict[str, str]] = {}          # pair path -> column -> file name

    def keep(self, index: int, pair: Pair, a: np.ndarray | None, e: np.ndarray | None) -> Pair:
        """Write the pair's pictures; returns the pair with FLIP's mean error when it was computed."""
        shown_pictures = {"actual": a, "expected": e}
        if _floats(a, e):
            shown_pictures = {"actual": floats.shown(a), "expected": floats.shown(e)}
            if a.shape[:2] == e.shape[:2]:
                shown_pictures["difference"] = floats.heat_map_floats(a, e, self.float_tolerance)
        elif comparable(a, e):
            shown_pictures["difference"] = gate.heat_map(a, e, self.tolerance)
            if self.flip:
                shown_pictures["flip"], mean = gate.flip_map(a, e)
                pair = dataclasses.replace(pair, flip_mean=mean)
        elif a is not None and e is not None and a.ndim == e.ndim == 2 and a.shape == e.shape:
            shown_pictures["difference"] = np.where((a != e)[..., None], np.uint8(255), np.uint8(0)).repeat(3, 2)
        names = {}
        for column, pixels in shown_pictures.items():
            if pixels is not None and pixels.dtype.kind == "f":
                pixels = floats.shown(pixels)                       # one float image of an odd pair
            if pixels is not None:
                names[column] = f"images/{index + 1:04d}-{column}.png"
                _save(os.path.join(self.tmp, names[column]), pixels)
        self.pictures[pair.path] = names
        return pair

    def finish(self, pairs: list[Pair], gate_text: str) -> None:
        rows = sorted(pairs, key=Pair.severity)
        text = page(rows, self.pictures, self.titles, gate_text, self.flip)
        with open(os.path.join(self.tmp, "index.html"), "w", encoding="utf-8", errors="backslashreplace") as f:
            f.write(text)
        open(os.path.join(self.tmp, MARKER), "w").close()

    def place(self) -> None:
        """Rename the finished report into place, replacing an earlier one (check_report_dir)."""
        os.chmod(self.tmp, 0o777 & ~current_umask())
        old = None
        if os.path.isdir(self.path):
            old = tempfile.mkdtemp(prefix=".rtcli-old-report-", dir=os.path.dirname(os.path.abspath(self.path)))
            os.rename(self.path, os.path.join(old, "report"))
        os.rename(self.tmp, self.path)
        if old:
            shutil.rmtree(old, ignore_errors=True)

    def discard(self) -> None:
        shutil.rmtree(self.tmp, ignore_errors=True)


def _floats(a: np.ndarray | None, e: np.ndarray | None) -> bool:
    """Whether both images of a pair are float images (EXR, PFM)."""
    return a is not None and e is not None and a.dtype.kind == "f" and e.dtype.kind == "f"


def _save(path: str, pixels: np.ndarray) -> None:
    """A picture for the page: colors as they are, id maps in their signature colors."""
    if pixels.ndim == 2:
        pixels = signature_colors(pixels.astype(np.int64))
    Image.fromarray(np.ascontiguousarray(pixels, dtype=np.uint8)).save(path, format="PNG", compress_level=3)
