"""Point lights with quadratic attenuation (notes 004), and optional spot and area lights.

A light is a list of sample points with intensities: a point light has one, an
area light n x n jittered points on its parallelogram, each with I / n^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.jitter import uniform
from rtcli.core.vec import dot


@dataclass(frozen=True)
class PointLight:
    position: np.ndarray                 # l, world space
    color: np.ndarray                    # I, intensity per channel
    attenuation: np.ndarray              # [c0, c1, c2]: 1/(c0 + c1 r + c2 r^2)
    spot_direction: np.ndarray | None = None   # unit axis of a spot light
    spot_cos: float = -1.0               # cos of the cone's half angle
    spot_falloff: float = 0.0            # exponent on cos between axis and -L inside the cone
    area_u: np.ndarray | None = None     # area light: edge vectors of the parallelogram
    area_v: np.ndarray | None = None
    area_samples: int = 1                # n: n x n points

    def attenuate(self, r: np.ndarray) -> np.ndarray:
        """att(r) = 1 / (c0 + c1 r + c2 r^2)."""
        c0, c1, c2 = self.attenuation
        return 1.0 / (c0 + c1 * r + c2 * r * r)

    def spot_factor(self, L: np.ndarray) -> np.ndarray:
        """1 outside of spot lights; for a spot, (cos angle)^falloff inside the cone, 0 outside."""
        if self.spot_direction is None:
            return np.ones(len(L))
        cos = -dot(L, self.spot_direction)
        return np.where(cos >= self.spot_cos, np.maximum(cos, 0) ** self.spot_falloff, 0.0)

    def sample_points(self, p: np.ndarray) -> list[np.ndarray]:
        """Positions to shade hit points p against: the light itself, or for an area
        light n x n points jittered within their cells (jitter hashed from p)."""
        if self.area_u is None:
            return [np.broadcast_to(self.position, p.shape)]
        k, points = self.area_samples, []
        for cell in range(k * k):
            a, b = divmod(cell, k)
            ju = uniform(p[:, 0], p[:, 1], p[:, 2], cell, 0)[:, None]
            jv = uniform(p[:, 0], p[:, 1], p[:, 2], cell, 1)[:, None]
            points.append(self.position + ((a + ju) / k - 0.5) * self.area_u
                          + ((b + jv) / k - 0.5) * self.area_v)
        return points
