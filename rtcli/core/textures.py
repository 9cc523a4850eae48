"""Textures: a color T that modulates ambient and diffuse (notes 000 11.7.2)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Checker:
    """POV-Ray's 3D checker in object space: c1 where floor(x/s)+floor(y/s)+floor(z/s) is even.

    Each coordinate is nudged by 1e-6 * size before the floor, so a surface lying
    on a cell boundary (a floor at y = 0) shows a clean pattern.
    """

    color1: np.ndarray
    color2: np.ndarray
    size: float = 1.0

    def color(self, p_object: np.ndarray, uv: np.ndarray) -> np.ndarray:
        cells = np.floor(p_object * (1 / self.size) + 1e-6).sum(axis=1)      # an integer, as a float
        return np.where((np.fmod(cells, 2) == 0)[:, None], self.color1, self.color2)


@dataclass(frozen=True)
class ImageTexture:
    """A picture mapped by the shape's (u, v): (0, 0) is the image's bottom-left corner.

    Bilinear filtering between texel centres. With `repeat` the picture tiles the
    (u, v) plane; without it, (u, v) are clamped to the picture's edges. Texel
    values are used as stored (byte / 255), like every other color of the scene.
    """

    texels: np.ndarray      # (h, w, 3) float, row 0 at the top
    repeat: bool = True

    def color(self, p_object: np.ndarray, uv: np.ndarray) -> np.ndarray:
        h, w, _ = self.texels.shape
        u, v = uv[:, 0], uv[:, 1]
        if self.repeat:
            u, v = u - np.floor(u), v - np.floor(v)
        x = np.clip(u, 0, 1) * w - 0.5                 # continuous texel coordinates
        y = (1 - np.clip(v, 0, 1)) * h - 0.5
        x0, y0 = np.floor(x), np.floor(y)
        fx, fy = (x - x0)[:, None], (y - y0)[:, None]
        wrap = (lambda k, n: k % n) if self.repeat else (lambda k, n: np.clip(k, 0, n - 1))
        xa, xb = wrap(x0.astype(np.int64), w), wrap(x0.astype(np.int64) + 1, w)
        ya, yb = wrap(y0.astype(np.int64), h), wrap(y0.astype(np.int64) + 1, h)
        t = self.texels
        top = t[ya, xa] * (1 - fx) + t[ya, xb] * fx
        bottom = t[yb, xa] * (1 - fx) + t[yb, xb] * fx
        return top * (1 - fy) + bottom * fy
