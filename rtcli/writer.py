"""Images out: 8-bit conversion, atomic PNG writing, the signature palette.

PNG files carry no timestamp or other metadata, so the same pixels always give
the same bytes. Files are written to a temporary name in the target folder and
renamed into place, so a failed run never leaves a truncated image.
"""

from __future__ import annotations

import colorsys
import os
import tempfile

import numpy as np
from PIL import Image

from rtcli.errors import RtcliError


def srgb_encode(c: np.ndarray) -> np.ndarray:
    """The sRGB transfer function on linear values in [0, 1]."""
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(np.maximum(c, 0.0031308), 1 / 2.4) - 0.055)


def to_8bit(image: np.ndarray, gamma: bool = False) -> np.ndarray:
    """Clamp to [0, 1], optionally sRGB-encode, and round(255 c)."""
    c = np.clip(image, 0.0, 1.0)
    if gamma:
        c = srgb_encode(c)
    return np.rint(c * 255).astype(np.uint8)


def write_png(path: str, pixels: np.ndarray) -> None:
    """Write uint8 (H, W, 3) as RGB or uint16 (H, W) as 16-bit gray, atomically."""
    if not ((pixels.dtype == np.uint16 and pixels.ndim == 2)
            or (pixels.dtype == np.uint8 and pixels.ndim == 3 and pixels.shape[2] == 3)):
        raise ValueError(f"cannot write {pixels.dtype} pixels of shape {pixels.shape} as PNG")
    img = Image.fromarray(pixels)                      # uint16 (H, W) -> I;16, uint8 (H, W, 3) -> RGB
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix=".rtcli-", suffix=".png", dir=folder)
    except OSError as e:
        raise RtcliError(f"cannot write {path}: {e.strerror}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            img.save(f, format="PNG", compress_level=3)  # zlib's 6 takes twice as long for 13% fewer bytes
        os.chmod(tmp, 0o666 & ~_umask())               # as a plain open() would (mkstemp makes 0600)
        os.replace(tmp, path)
    except BaseException as e:
        os.unlink(tmp)
        if isinstance(e, OSError):
            raise RtcliError(f"cannot write {path}: {e.strerror or e}") from None
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def palette(count: int) -> np.ndarray:
    """(count + 1, 3) uint8: black for id 0, then a fixed, distinct color per id.

    Hues step by the golden ratio (neighbouring ids land far apart on the color
    wheel) and saturation and value cycle through a few levels, so even ids whose
    hues come close again differ in brightness.
    """
    colors = [(0, 0, 0)]
    for k in range(1, count + 1):
        hue = (k * 0.6180339887498949) % 1.0
        sat = (0.95, 0.55, 0.8)[k % 3]
        val = (1.0, 0.7)[(k // 3) % 2]
        colors.append(tuple(round(255 * c) for c in colorsys.hsv_to_rgb(hue, sat, val)))
    return np.array(colors, dtype=np.uint8)


def signature_colors(ids: np.ndarray) -> np.ndarray:
    """The color-coded signature picture of an id map."""
    return palette(int(ids.max(initial=0)))[ids]
