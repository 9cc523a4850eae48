"""Comparing two images through the golden gate, for the Python API and `rtcli compare`.

rtcli.diff(actual, expected) applies compare.py's gate (its docstring states the
rule and its defaults) and returns a Difference: whether it passes, the summary
line `rtcli compare` prints, the numbers, and the heat map (and FLIP's map, when
asked) as ImageArrays. In Jupyter a Difference shows its heat map.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from rtcli.api.options import check_options, check_path
from rtcli.api.results import ImageArray, png_bytes
from rtcli.compare import images as gate
from rtcli.core.display import to_8bit
from rtcli.errors import RtcliError

GATE = {"tolerance": 2, "max_bad_pixels": 16, "max_bad_fraction": 1e-4, "max_cluster": 3}
ID_GATE = {"max_boundary_mismatch": 8, "max_boundary_fraction": 0.01}


@dataclass(frozen=True)
class Difference:
    """The outcome of comparing two images (or id maps)."""

    comparison: gate.Comparison               # the numbers: bad pixels, limit, clusters, errors
    heat_map: ImageArray | None = field(default=None, repr=False)   # None for id maps or sizes that differ
    flip_map: ImageArray | None = field(default=None, repr=False)   # with flip=True
    flip_mean: float | None = None

    @property
    def ok(self) -> bool:
        return self.comparison.ok

    @property
    def summary(self) -> str:
        """The line `rtcli compare` prints, with FLIP's mean error when it was computed."""
        extra = f", mean FLIP {self.flip_mean:.4f}" if self.flip_mean is not None else ""
        return self.comparison.summary + extra

    def __repr__(self) -> str:
        return f"<rtcli.Difference {self.summary}>"

    def _repr_png_(self) -> bytes | None:
        return None if self.heat_map is None else png_bytes(np.asarray(self.heat_map))


def diff(actual, expected, *, flip: bool = False, **options) -> Difference:
    """Compare `actual` with `expected` by the golden gate: each an image path (PNG), a Pillow image
    or an array (uint8 (H, W, 3); float linear colors, converted as the renderer writes them;
    uint16 (H, W) signature ids, compared as `rtcli compare --ids` does).

    options: tolerance, max_bad_pixels, max_bad_fraction, max_cluster (colors) and
    max_boundary_mismatch, max_boundary_fraction (ids), with the command line's defaults.
    flip=True adds NVIDIA FLIP's perceptual error map (needs the `flip` extra).
    """
    unknown = set(options) - set(GATE) - set(ID_GATE)
    if unknown:
        raise TypeError(f"diff() got unknown options: {', '.join(sorted(unknown))}")
    check_options(flip=flip, **options)
    a, e = pixels(actual, "actual"), pixels(expected, "expected")
    image_options = {k: options.get(k, v) for k, v in GATE.items()}
    id_options = {k: options.get(k, v) for k, v in ID_GATE.items()}
    result = gate.compare(a, e, image_options, id_options)
    comparable = a.shape == e.shape and a.ndim == 3
    heat = ImageArray(gate.heat_map(a, e, image_options["tolerance"])) if comparable else None
    if flip and comparable:
        picture, mean = gate.flip_map(a, e)
        return Difference(result, heat, ImageArray(picture), mean)
    return Difference(result, heat)


def pixels(image, name: str = "image") -> np.ndarray:
    """An image as compare.py takes it: uint8 (H, W, 3) or an integer (H, W) id map."""
    if isinstance(image, (str, os.PathLike)):
        return gate.read_png(check_path(name, image))
    if hasattr(image, "mode") and hasattr(image, "size"):           # a Pillow image
        return np.asarray(image if image.mode in ("RGB", "L", "I", "I;16") else image.convert("RGB"))
    array = np.asarray(image)
    if array.dtype.kind == "f":
        if array.ndim != 3 or array.shape[2] != 3:
            raise RtcliError(f"{name} is not an RGB image (H, W, 3): got {array.dtype} array of shape {array.shape}")
        return to_8bit(array)
    return array
