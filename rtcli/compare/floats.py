"""EXR and PFM in the golden gate: linear colors compared as floats, with a tolerance in linear
values, and the id layer of a multi-layer EXR compared as `--ids` compares id maps; and the
provenance of both images, whose differences `rtcli compare` notes (README.md, Images).

A pixel of a float image is bad when a channel differs by more than `float_tolerance` (default
0.01) times the larger of 1 and the expected value: an absolute tolerance up to 1, a relative
one above (radiance is unbounded). NaN equals NaN and an infinity the same infinity. The
counts, the cluster rule and their limits are the 8-bit gate's (images.py). An EXR's color is
compared as stored (premultiplied by A when it has A, and A with it).
"""

from __future__ import annotations

import os

import numpy as np

from rtcli.compare import images as gate
from rtcli.core.display import to_8bit
from rtcli.errors import plural
from rtcli.rendering.exr import LAYERS, color_of, read_exr
from rtcli.rendering.pfm import read_pfm
from rtcli.rendering.reading import about

FLOAT_TOLERANCE = 0.01
FLOATS = (".exr", ".pfm")
IDS = LAYERS["ids"][0]


class Decoded(np.ndarray):
    """A decoded image (read_png's arrays, or float32 (H, W, 3 or 4) for EXR and PFM) with its
    provenance (`meta`) and an EXR's id layer (`ids`, None without one)."""

    meta: dict
    ids: np.ndarray | None

    def __new__(cls, pixels, meta=None, ids=None) -> Decoded:
        image = np.asarray(pixels).view(cls)
        image.meta, image.ids = dict(meta or {}), ids
        return image

    def __array_finalize__(self, obj) -> None:
        self.meta, self.ids = getattr(obj, "meta", {}), getattr(obj, "ids", None)


def read_image(path: str) -> Decoded:
    """An image for the gate: a PNG as read_png decodes it, an EXR's or PFM's linear colors;
    with its provenance. RtcliError naming the file when it cannot be read."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".exr":
        channels, meta = read_exr(path, gate.MAX_PIXELS)
        ids = channels.get(IDS)
        return Decoded(color_of(channels, path), meta, None if ids is None else ids.astype(np.int64))
    if ext == ".pfm":
        about(path)                                        # a regular file within the limits, or the error
        colors = read_pfm(path, gate.MAX_PIXELS)
        return Decoded(colors if colors.ndim == 3 else np.repeat(colors[..., None], 3, axis=2))
    pixels = gate.read_png(path)
    return Decoded(pixels, about(path).meta)


def compare_any(actual, expected, image_options: dict, id_options: dict) -> gate.Comparison:
    """The gate for any two decoded images: 8-bit pictures and id maps as images.compare does
    (image_options without float_tolerance), float images here; and two EXRs' id layers too."""
    options = {k: v for k, v in image_options.items() if k != "float_tolerance"}
    a_float, e_float = np.asarray(actual).dtype.kind == "f", np.asarray(expected).dtype.kind == "f"
    if not (a_float or e_float):
        return gate.compare(actual, expected, options, id_options)
    if a_float != e_float:
        kind = {True: "linear floats (EXR, PFM)", False: "an 8-bit image or an id map"}
        return gate.Comparison(False, f"FAIL: kind differs: actual is {kind[a_float]}, expected is {kind[e_float]}")
    result = compare_floats(actual, expected, image_options.get("float_tolerance", FLOAT_TOLERANCE),
                            **{k: v for k, v in options.items() if k != "tolerance"})
    a_ids, e_ids = getattr(actual, "ids", None), getattr(expected, "ids", None)
    if a_ids is None or e_ids is None:
        return result
    ids = gate.compare_ids(a_ids, e_ids, **id_options)
    ok = result.ok and ids.ok
    summary = f"{'OK' if ok else 'FAIL'}: {_body(result)}; id layer: {_body(ids)}"
    return gate.Comparison(ok, summary, result.bad_pixels, result.limit, result.largest_cluster, result.cluster_at,
                           result.max_error, result.max_error_at, result.mean_error)


def _body(c: gate.Comparison) -> str:
    return c.summary.split(": ", 1)[1]


def float_errors(actual: np.ndarray, expected: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, the largest channel error |a - e| and whether it is beyond the tolerance (see the
    module docstring), over the channels both images have."""
    n = min(actual.shape[2], expected.shape[2])
    a, e = actual[..., :n].astype(np.float64), expected[..., :n].astype(np.float64)
    with np.errstate(invalid="ignore"):
        same = (a == e) | (np.isnan(a) & np.isnan(e))
        d = np.where(same, 0.0, np.abs(a - e))
        d = np.where(np.isnan(d), np.inf, d)
        bad = d > tolerance * np.maximum(1.0, np.where(np.isfinite(e), np.abs(e), 1.0))
    return d.max(axis=2), bad.any(axis=2)


def compare_floats(actual, expected, float_tolerance: float = FLOAT_TOLERANCE, max_bad_pixels: int = 16,
                   max_bad_fraction: float = 1e-4, max_cluster: int = 3) -> gate.Comparison:
    """The gate on two float images (H, W, channels), in linear values."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    if (differs := gate._size_differs(actual, expected)) is not None:
        return differs
    h, w = actual.shape[:2]
    err, bad = float_errors(actual, expected, float_tolerance)
    n_bad, limit = int(np.count_nonzero(bad)), gate._limit(max_bad_pixels, max_bad_fraction, h * w)
    cluster, cluster_at = gate._largest_cluster(bad) if n_bad else (0, None)
    worst = float(err.max()) if err.size else 0.0
    worst_at = gate._xy(np.argmax(err), w) if worst > 0 else None
    finite = err[np.isfinite(err)]
    mean = float(finite.mean()) if finite.size else 0.0
    ok = n_bad <= limit and cluster <= max_cluster
    summary = (f"{'OK' if ok else 'FAIL'}: {plural(n_bad, 'bad pixel')} (limit {limit}), "
               f"largest cluster {cluster} px{gate._at(cluster_at)}, max error {worst:.6g}{gate._at(worst_at)}, "
               f"mean error {mean:.3g} (linear, tolerance {float_tolerance:g})")
    return gate.Comparison(ok, summary, n_bad, limit, cluster, cluster_at, worst, worst_at, mean)


def heat_map_floats(actual: np.ndarray, expected: np.ndarray, float_tolerance: float = FLOAT_TOLERANCE) -> np.ndarray:
    """The heat map of two float images, in the 8-bit heat map's colors: an error of one tolerance
    shows as two levels of 255, so a bad pixel is orange or brighter and a good one dark red."""
    err, bad = float_errors(np.asarray(actual), np.asarray(expected), float_tolerance)
    levels = np.where(err > 0, np.ceil(np.minimum(err / float_tolerance * 2, 255)), 0)
    levels = np.where(bad, np.maximum(levels, 3), np.minimum(levels, 2)).astype(np.int32)
    return gate.ramp(levels, 2)


def shown(pixels: np.ndarray) -> np.ndarray:
    """A float image as a picture for the report: its color clamped to [0, 1], as 8 bits."""
    return to_8bit(np.asarray(pixels)[..., :3])
