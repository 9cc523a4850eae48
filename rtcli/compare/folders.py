"""`rtcli compare ACTUAL_DIR EXPECTED_DIR`: images paired by relative path, the gate per pair.

Every .png, .exr and .pfm under either folder (subfolders too) is paired with the file
of the same relative path under the other. Each pair goes through compare.py's gate, as
`rtcli compare` on two files does (a color image, or a 16-bit signature id map; float
images and an EXR's id layer by floats.py), and its notes say when the two images' provenance
differs (other settings, another rtcli). A pair
is ok, failing, missing (no actual image for an expected one), extra (an actual
image without an expected one) or unreadable (a file that is not a readable PNG);
anything but ok fails the run. An unreadable file fails its pair, not the run, so
one broken image still gets every other pair compared and reported. A missing or
unreadable pair is an error (it could not be compared: a scene that failed to render
leaves its golden without an image), a failing or extra one a failure (README.md,
Commands; the JUnit file and the report tell them apart).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rtcli.compare import images as gate
from rtcli.compare.floats import compare_any, read_image
from rtcli.errors import RtcliError, one_line, plural, shown
from rtcli.rendering.provenance import differences

IMAGES = (".png", ".exr", ".pfm")
RANK = {"unreadable": 0, "missing": 1, "extra": 2, "failing": 3, "ok": 4}      # worst first
ERRORS = ("unreadable", "missing")                # not compared; the other statuses but ok are failures


@dataclass(frozen=True)
class Pair:
    """One relative path and what comparing it gave."""

    path: str                              # relative, with / separators
    status: str                            # a key of RANK
    summary: str                           # the line printed for it
    comparison: gate.Comparison | None = None
    seconds: float = 0.0
    flip_mean: float | None = None
    notes: tuple[str, ...] = ()                # provenance.differences: other settings, another rtcli

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def result(self) -> str:
        """"ok", "error" (the pair could not be compared) or "failure" (see the module docstring)."""
        return "ok" if self.ok else "error" if self.status in ERRORS else "failure"

    def severity(self) -> tuple:
        """Sort key, worst first: status, then bad pixels, then mean error."""
        c = self.comparison
        return (RANK[self.status], -(c.bad_pixels if c else 0), -(c.mean_error if c else 0), self.path)


def images_under(folder: str) -> dict[str, str]:
    """relative path (with /) -> path of every image (IMAGES) under `folder`, skipping rtcli's temporary
    files."""
    if not os.path.isdir(folder):
        raise RtcliError(f"{shown(folder)}: not a folder (give two folders, or two images)")
    found = {}
    for root, dirs, files in os.walk(folder):
        dirs.sort()
        for name in files:
            if name.lower().endswith(IMAGES) and not name.startswith(".rtcli-"):
                path = os.path.join(root, name)
                found[os.path.relpath(path, folder).replace(os.sep, "/")] = path
    return found


def compare_folders(actual_dir: str, expected_dir: str, image_options: dict, id_options: dict,
                    keep: Callable | None = None) -> list[Pair]:
    """Every pair's outcome, in path order. `keep(index, pair, actual, expected)` receives the
    decoded pixels (None where absent or unreadable) of each, for a report."""
    actual, expected = images_under(actual_dir), images_under(expected_dir)
    if not actual and not expected:
        raise RtcliError(f"no .png, .exr or .pfm images under {shown(actual_dir)} or {shown(expected_dir)}")
    pairs = []
    for index, path in enumerate(sorted(set(actual) | set(expected))):
        start = time.perf_counter()
        pair, a, e = _compare_one(path, actual.get(path), expected.get(path), image_options, id_options)
        if keep is not None:
            pair = keep(index, pair, a, e) or pair
        pairs.append(Pair(pair.path, pair.status, pair.summary, pair.comparison,
                          time.perf_counter() - start, pair.flip_mean, pair.notes))
    return pairs


def _compare_one(path, actual, expected, image_options, id_options):
    a = e = None
    try:
        a = read_image(actual) if actual else None
        e = read_image(expected) if expected else None
    except RtcliError as error:
        return Pair(path, "unreadable", f"UNREADABLE: {one_line(str(error))}"), a, e
    if a is None:
        return Pair(path, "missing", f"MISSING: no actual image for {shown(expected)}"), a, e
    if e is None:
        return Pair(path, "extra", f"EXTRA: no expected image for {shown(actual)}"), a, e
    result = compare_any(a, e, image_options, id_options)
    notes = tuple(differences(a.meta, e.meta))
    return Pair(path, "ok" if result.ok else "failing", result.summary, result, notes=notes), a, e


def counts(pairs: list[Pair]) -> dict[str, int]:
    """How many pairs have each status."""
    found = {status: 0 for status in RANK}
    for p in pairs:
        found[p.status] += 1
    return found


def total_line(pairs: list[Pair]) -> str:
    """The last line `rtcli compare` prints for two folders."""
    c = counts(pairs)
    verdict = "OK" if c["ok"] == len(pairs) else "FAIL"
    return (f"{verdict}: {plural(len(pairs), 'pair')}: {c['ok']} ok, {c['failing']} failing, {c['missing']} missing, "
            f"{c['extra']} extra, {c['unreadable']} unreadable")


def comparable(a: np.ndarray | None, e: np.ndarray | None) -> bool:
    """Whether two decoded images are color pictures of one size (a heat map and FLIP apply)."""
    return a is not None and e is not None and a.ndim == 3 and a.shape == e.shape
