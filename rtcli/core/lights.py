"""Point lights with quadratic attenuation (notes 004), and optional spot and area lights.

A light is a list of sample points with intensities: a point light has one, an
area light n x n jittered points on its parallelogram, each with I / n^2. For the
kernels a light is a row of floats (`PointLight.row`), read by the names below.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.elementary import power
from rtcli.core.jitter import hash_point
from rtcli.core.vec import dot
from rtcli.kernels.variants import kernel, maximum, select, sqrt

# The light row: position l, color I, attenuation [c0, c1, c2], spot? (1 or 0), the spot's unit
# axis, cos of its half angle and falloff exponent, area samples n (0: a point), edges u and v.
POSITION, COLOR, ATTENUATION, IS_SPOT, SPOT_AXIS, SPOT_COS, SPOT_FALLOFF, AREA_N, AREA_U, AREA_V = (
    0, 3, 6, 9, 10, 13, 14, 15, 16, 19)
LIGHT_WIDTH = 22


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

    @property
    def samples(self) -> int:
        """How many points stand for the light: 1, or n x n for an area light."""
        return 1 if self.area_u is None else self.area_samples ** 2

    @property
    def row(self) -> np.ndarray:
        spot, area = self.spot_direction is not None, self.area_u is not None
        zero = np.zeros(3)
        return np.array([*self.position, *self.color, *self.attenuation, float(spot),
                         *(self.spot_direction if spot else zero), self.spot_cos, self.spot_falloff,
                         self.area_samples if area else 0, *(self.area_u if area else zero),
                         *(self.area_v if area else zero)], dtype=float)


@kernel
def sample_point(light, cell, px, py, pz):
    """Sample `cell` of the light, as seen from the hit point p: the light's position, or for an
    area light the point jittered within cell (a, b) of its n x n grid (jitter hashed from p)."""
    n = light[AREA_N]
    if n == 0:
        return light[POSITION], light[POSITION + 1], light[POSITION + 2]
    fu = (cell // n + hash_point(px, py, pz, cell, 0)) / n - 0.5
    fv = (cell % n + hash_point(px, py, pz, cell, 1)) / n - 0.5
    return (light[POSITION] + fu * light[AREA_U] + fv * light[AREA_V],
            light[POSITION + 1] + fu * light[AREA_U + 1] + fv * light[AREA_V + 1],
            light[POSITION + 2] + fu * light[AREA_U + 2] + fv * light[AREA_V + 2])


@kernel
def toward(qx, qy, qz, px, py, pz):
    """(L, r): the unit vector from p to the light point q, and the distance r."""
    lx, ly, lz = qx - px, qy - py, qz - pz
    r = sqrt(lx * lx + ly * ly + lz * lz)
    return lx / r, ly / r, lz / r, r


@kernel
def attenuation(light, r):
    """att(r) = 1 / (c0 + c1 r + c2 r^2) (notes 004)."""
    return 1.0 / (light[ATTENUATION] + light[ATTENUATION + 1] * r + light[ATTENUATION + 2] * r * r)


@kernel
def spot_factor(light, Lx, Ly, Lz):
    """1 for a point light; for a spot, (cos of the angle between its axis and -L)^falloff inside the
    cone and 0 outside."""
    if light[IS_SPOT] == 0:
        return 1.0
    cos = -dot(Lx, Ly, Lz, light[SPOT_AXIS], light[SPOT_AXIS + 1], light[SPOT_AXIS + 2])
    return select(cos >= light[SPOT_COS], power(maximum(cos, 0.0), light[SPOT_FALLOFF]), 0.0)


@kernel
def weight(light, r, Lx, Ly, Lz, samples):
    """The share of I reaching the point: att(r) times the spot factor, over the number of the
    light's sample points."""
    return attenuation(light, r) * spot_factor(light, Lx, Ly, Lz) / samples
