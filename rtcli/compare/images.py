"""Golden-image comparison on decoded pixels (never file bytes).

Color images are uint8 arrays (H, W, 3).  The gate, with its documented defaults:

* a pixel is *bad* if any channel differs by more than ``tolerance=2`` of 255;
* the comparison FAILS if the number of bad pixels exceeds
  ``max(max_bad_pixels=16, floor(max_bad_fraction=0.0001 * H * W))``,
  or if any 8-connected cluster of bad pixels is larger than ``max_cluster=3``
  (so a cluster of 4 or more pixels fails even when the count is tiny).

Signature id maps are integer arrays (H, W), compared exactly, except that
mismatches on pixels lying on an id boundary of the EXPECTED map (a pixel whose
8-neighbourhood in expected holds a different id) are forgiven up to
``max(max_boundary_mismatch=8, floor(max_boundary_fraction=0.01 * boundary pixels))``.
Any mismatch off the boundary fails.

Different sizes always fail ("size differs: actual 640x480, expected 320x240").
Every comparison yields a one-line summary starting with "OK:" or "FAIL:".
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from PIL import Image
from scipy import ndimage

from rtcli.errors import RtcliError, plural, shown
from rtcli.scenefile.files import InputError, check_input

_EIGHT = np.ones((3, 3), dtype=int)     # 8-connectivity for ndimage.label


@dataclass(frozen=True)
class Comparison:
    """Outcome of one comparison; locations are (x, y), i.e. (column, row).

    Color mode fills the error fields; id mode counts mismatched ids in
    bad_pixels, the boundary allowance in limit, and the off/on-boundary split.
    """

    ok: bool
    summary: str                              # one line, "OK: ..." or "FAIL: ..."
    bad_pixels: int = 0                       # color: beyond tolerance; ids: all mismatches
    limit: int = 0                            # color: bad-pixel limit; ids: on-boundary limit
    largest_cluster: int = 0                  # color only: biggest 8-connected bad cluster
    cluster_at: tuple[int, int] | None = None     # its first pixel in raster order
    max_error: int = 0                        # color only: max over pixels and channels
    max_error_at: tuple[int, int] | None = None
    mean_error: float = 0.0                   # color only: mean |a-e| over pixels and channels
    off_boundary: int = 0                     # ids only
    boundary_pixels: int = 0                  # ids only


def _limit(count: int, fraction: float, n: int) -> int:
    return max(count, math.floor(fraction * n + 1e-9))


def _xy(flat_index: int, width: int) -> tuple[int, int]:
    y, x = divmod(int(flat_index), width)
    return x, y


def _at(xy: tuple[int, int] | None) -> str:
    return f" at (x={xy[0]}, y={xy[1]})" if xy is not None else ""


def _check(arr, ndim: int, name: str, what: str) -> np.ndarray:
    arr = np.asarray(arr)
    if arr.ndim != ndim or (ndim == 3 and arr.shape[2] != 3) or arr.dtype.kind not in "iub":
        raise RtcliError(f"{name} is not {what}: got {arr.dtype} array of shape {arr.shape}")
    return arr


def _size_differs(actual: np.ndarray, expected: np.ndarray) -> Comparison | None:
    if actual.shape[:2] == expected.shape[:2]:
        return None
    (ah, aw), (eh, ew) = actual.shape[:2], expected.shape[:2]
    return Comparison(False, f"FAIL: size differs: actual {aw}x{ah}, expected {ew}x{eh}")


def _largest_cluster(bad: np.ndarray) -> tuple[int, tuple[int, int] | None]:
    """Size of the largest 8-connected cluster of True pixels and its first pixel.

    Only the box around the bad pixels is labelled, so a few bad pixels in a big
    image cost little memory.
    """
    rows, cols = np.flatnonzero(bad.any(axis=1)), np.flatnonzero(bad.any(axis=0))
    if len(rows) == 0:
        return 0, None
    y0, x0 = rows[0], cols[0]
    labels, count = ndimage.label(bad[y0:rows[-1] + 1, x0:cols[-1] + 1], structure=_EIGHT)
    sizes = np.bincount(labels.ravel())[1:]
    best = int(np.argmax(sizes)) + 1
    y, x = divmod(int(np.argmax(labels.ravel() == best)), labels.shape[1])
    return int(sizes[best - 1]), (int(x + x0), int(y + y0))


BAND = 512                              # rows compared at a time: small integer arrays, bounded memory
MAX_PIXELS = 40_000_000                 # per image (8K UHD is 33.2 million); see read_png


def _band_errors(actual: np.ndarray, expected: np.ndarray) -> tuple[np.ndarray, int]:
    """Per pixel, the largest channel error |a - e| (uint8 for 8-bit images), and the sum of all
    channel errors, computed in bands of rows with small integer types."""
    small = actual.dtype == np.uint8 and expected.dtype == np.uint8
    work, keep = (np.int16, np.uint8) if small else (np.int64, np.int64)
    pixel_err = np.empty(actual.shape[:2], dtype=keep)
    total = 0
    for y in range(0, actual.shape[0], BAND):
        d = np.abs(actual[y:y + BAND].astype(work) - expected[y:y + BAND].astype(work))
        pixel_err[y:y + BAND] = d.max(axis=2)
        total += int(d.sum(dtype=np.int64))
    return pixel_err, total


def compare_images(actual, expected, tolerance: int = 2, max_bad_pixels: int = 16,
                   max_bad_fraction: float = 1e-4, max_cluster: int = 3) -> Comparison:
    """Apply the color gate (see the module docstring) to two (H, W, 3) images."""
    actual = _check(actual, 3, "actual", "an RGB image (H, W, 3)")
    expected = _check(expected, 3, "expected", "an RGB image (H, W, 3)")
    if (differs := _size_differs(actual, expected)) is not None:
        return differs
    h, w = actual.shape[:2]
    pixel_err, total = _band_errors(actual, expected)
    bad = pixel_err > tolerance
    n_bad, limit = int(np.count_nonzero(bad)), _limit(max_bad_pixels, max_bad_fraction, h * w)
    cluster, cluster_at = _largest_cluster(bad) if n_bad else (0, None)
    max_err = int(pixel_err.max()) if pixel_err.size else 0
    max_at = _xy(np.argmax(pixel_err), w) if max_err > 0 else None
    mean = total / (h * w * 3) if h * w else 0.0
    ok = n_bad <= limit and cluster <= max_cluster
    summary = (f"{'OK' if ok else 'FAIL'}: {plural(n_bad, 'bad pixel')} (limit {limit}), "
               f"largest cluster {cluster} px{_at(cluster_at)}, "
               f"max error {max_err}/255{_at(max_at)}, mean error {mean:.2f}/255")
    return Comparison(ok, summary, n_bad, limit, cluster, cluster_at, max_err, max_at, mean)


def id_boundary(ids: np.ndarray) -> np.ndarray:
    """True where the 8-neighbourhood of a pixel holds a different id (image edge is not one)."""
    lo = ndimage.minimum_filter(ids, size=3, mode="nearest")
    hi = ndimage.maximum_filter(ids, size=3, mode="nearest")
    return (lo != ids) | (hi != ids)


def compare_ids(actual, expected, max_boundary_mismatch: int = 8,
                max_boundary_fraction: float = 0.01) -> Comparison:
    """Compare two (H, W) id maps exactly, forgiving a few mismatches on expected's id boundaries."""
    actual = _check(actual, 2, "actual", "an id map (H, W)")
    expected = _check(expected, 2, "expected", "an id map (H, W)")
    if (differs := _size_differs(actual, expected)) is not None:
        return differs
    boundary = id_boundary(expected)
    wrong = actual != expected
    off, on = wrong & ~boundary, wrong & boundary
    n_off, n_on, n_boundary = int(off.sum()), int(on.sum()), int(boundary.sum())
    limit = _limit(max_boundary_mismatch, max_boundary_fraction, n_boundary)
    ok = n_off == 0 and n_on <= limit
    summary = (f"{'OK' if ok else 'FAIL'}: {plural(n_off + n_on, 'mismatched id')} ({n_off} off boundary, "
               f"{n_on} on boundary, limit {limit} of {plural(n_boundary, 'boundary pixel')})")
    first = off if n_off else on
    if n_off or n_on:
        i = int(np.argmax(first.ravel()))
        x, y = _xy(i, expected.shape[1])
        summary += (f", first {'off' if n_off else 'on'}-boundary at (x={x}, y={y}): "
                    f"actual {actual.ravel()[i]}, expected {expected.ravel()[i]}")
    return Comparison(ok, summary, n_off + n_on, limit, off_boundary=n_off,
                      boundary_pixels=n_boundary)


def compare(actual: np.ndarray, expected: np.ndarray, image_options: dict | None = None,
            id_options: dict | None = None) -> Comparison:
    """Dispatch on what read_png returned: (H, W, 3) -> compare_images, (H, W) -> compare_ids,
    each with its own options."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    if {actual.ndim, expected.ndim} == {2, 3}:
        if (differs := _size_differs(actual, expected)) is not None:
            return differs
        kind = {2: "an id map", 3: "an RGB image"}
        return Comparison(False, f"FAIL: kind differs: actual is {kind[actual.ndim]}, "
                                 f"expected is {kind[expected.ndim]}")
    if actual.ndim == 2:
        return compare_ids(actual, expected, **(id_options or {}))
    return compare_images(actual, expected, **(image_options or {}))


def heat_map(actual, expected, tolerance: int = 2) -> np.ndarray:
    """A uint8 (H, W, 3) picture of where and how much two RGB images differ.

    Per pixel, e = max over channels of |actual - expected| (0..255), mapped to
    an intensity t: t = 0 if e == 0, else min(255, 32 + 8*e), so one level is
    already visible; bad pixels (e > tolerance) get t >= 128 so they stand out.
    t goes through a black -> red -> yellow -> white ramp:
    (R, G, B) = clip(3t, 3t - 255, 3t - 510 to 0..255).  Thus equal pixels are
    black, e = 1 and 2 are dark red (120, 144), the first bad levels are orange
    (255, 129, 0) and e >= 28 is white.  Sizes must match.
    """
    actual = _check(actual, 3, "actual", "an RGB image (H, W, 3)")
    expected = _check(expected, 3, "expected", "an RGB image (H, W, 3)")
    if (differs := _size_differs(actual, expected)) is not None:
        raise RtcliError(differs.summary.removeprefix("FAIL: "))
    out = np.empty(actual.shape, dtype=np.uint8)
    for y in range(0, actual.shape[0], BAND):
        out[y:y + BAND] = ramp(_band_errors(actual[y:y + BAND], expected[y:y + BAND])[0].astype(np.int32), tolerance)
    return out


def ramp(e: np.ndarray, tolerance: int) -> np.ndarray:
    """The heat map's colors (see heat_map) of per-pixel errors e (integers 0..255)."""
    t = np.where(e > 0, np.minimum(255, 32 + 8 * e), 0)
    t = np.where(e > tolerance, np.maximum(t, 128), t)
    return np.clip(3 * t[..., None] - np.array([0, 255, 510], np.int32), 0, 255).astype(np.uint8)


def read_png(path) -> np.ndarray:
    """Decode a PNG: uint8 RGB (H, W, 3) for color (RGBA, palette ... converted to RGB);
    the 2-D integer array for single-channel PNGs (modes I;16, I, L), as used by id mode.

    Raises RtcliError naming the file if it is missing, not a regular file, not a
    readable PNG, or larger than MAX_PIXELS (checked from its header, before decoding):
    a comparison holds both images (3 bytes per pixel each) and a few bytes per pixel
    more, about 500 MB at the limit with --diff.
    """

    try:
        check_input(path, 1 << 40)
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(path) as img:
                if img.format != "PNG":
                    raise RtcliError(f"{shown(path)}: not a PNG file (it is {img.format})")
                w, h = img.size
                if w * h > MAX_PIXELS:
                    raise RtcliError(f"{shown(path)}: {w}x{h} is {w * h:,} pixels, more than the {MAX_PIXELS:,} "
                                     "rtcli compare accepts")
                img.load()
                if img.mode in ("L", "I") or img.mode.startswith("I;16"):
                    return np.asarray(img)
                return np.asarray(img if img.mode == "RGB" else img.convert("RGB"))
    except FileNotFoundError:
        raise RtcliError(f"{shown(path)}: no such file") from None
    except InputError as exc:
        raise RtcliError(f"{shown(path)}: cannot read: {exc}") from None
    except (Image.DecompressionBombError, Image.DecompressionBombWarning):
        raise RtcliError(f"{shown(path)}: more than the {MAX_PIXELS:,} pixels rtcli compare accepts") from None
    except (OSError, ValueError, SyntaxError, EOFError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise RtcliError(f"{shown(path)}: not a readable PNG: {reason}") from None


def flip_map(actual: np.ndarray, expected: np.ndarray) -> tuple[np.ndarray, float]:
    """NVIDIA FLIP's perceptual error map (magma colors, uint8) and its mean, for two RGB images.

    Needs the optional flip-evaluator package (`pip install -e '.[flip]'` in the rtcli folder).
    """
    try:
        import flip_evaluator  # the flip extra, optional: only for --metric flip
    except ImportError:
        raise RtcliError("--flip needs the flip-evaluator package: pip install -e '.[flip]' in the rtcli "
                         "folder (rtcli is not on the package index)") from None
    if actual.ndim != 3 or actual.shape != expected.shape:
        raise RtcliError("--flip compares two RGB images of the same size")
    error, mean, _ = flip_evaluator.evaluate(expected.astype(np.float32) / 255,
                                             actual.astype(np.float32) / 255, "LDR")
    return np.rint(np.clip(error, 0, 1) * 255).astype(np.uint8), float(mean)
