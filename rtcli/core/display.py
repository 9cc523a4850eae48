"""How colors and ids are shown: linear colors as 8-bit pixels (clamped to [0, 1], rounded, and
sRGB-encoded for `--gamma`), and the signature's palette, a fixed color per object id.
"""

from __future__ import annotations

import colorsys

import numpy as np

from rtcli.core.elementary import power


def srgb_encode(c: np.ndarray) -> np.ndarray:
    """The sRGB transfer function on linear values in [0, 1]."""
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * power(np.maximum(c, 0.0031308), 1 / 2.4) - 0.055)


def to_8bit(image: np.ndarray, gamma: bool = False) -> np.ndarray:
    """Clamp to [0, 1], optionally sRGB-encode, and round(255 c)."""
    c = np.clip(image, 0.0, 1.0)
    if gamma:
        c = srgb_encode(c)
    return np.rint(c * 255).astype(np.uint8)


def to_8bit_alpha(image: np.ndarray, gamma: bool = False) -> np.ndarray:
    """(..., 4) straight colors and alpha: the colors as to_8bit, the alpha round(255 a) (never
    sRGB-encoded)."""
    return np.concatenate([to_8bit(image[..., :3], gamma), to_8bit(image[..., 3:])], axis=-1)


def to_16bit(image: np.ndarray, gamma: bool = False) -> np.ndarray:
    """(..., 3) or (..., 4) linear colors (and straight alpha) as 16-bit: clamped to [0, 1], the
    colors optionally sRGB-encoded, round(65535 c)."""
    c = np.clip(image, 0.0, 1.0)
    if gamma:
        c = np.concatenate([srgb_encode(c[..., :3]), c[..., 3:]], axis=-1)
    return np.rint(c * 65535).astype(np.uint16)


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
