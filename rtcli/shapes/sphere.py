"""Sphere (notes 000 11.3.3, 002): |P - center|^2 = radius^2.

YAML: `sphere: {center: [0, 0, 0], radius: 1}`; both optional (the generic unit sphere).
(u, v): u the longitude around +y (0.5 faces +z), v the latitude, 0 at the south pole.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.core.elementary import arcsin, arctan2
from rtcli.core.vec import dot
from rtcli.shapes.base import Param, Shape, ShapeKernels
from rtcli.kernels.variants import (
    INF,
    copysign,
    isfinite,
    kernel,
    maximum,
    minimum,
    not_,
    select,
    sqrt,
)

CENTER, RADIUS, RADIUS2 = 0, 3, 4                     # the row: center (3), r, r^2


@kernel
def roots(s, ox, oy, oz, dx, dy, dz):
    """Both roots of A t^2 + 2B t + C = 0, A = |d|^2, B = S.d, C = |S|^2 - r^2, S = o - center.

    The notes' t = (-B -+ sqrt(B^2 - AC)) / A, computed as q/A and C/q with
    q = -B - sign(B) sqrt(B^2 - AC), which avoids cancellation. (t_near, t_far), inf on a miss.
    """
    Sx, Sy, Sz = ox - s[CENTER], oy - s[CENTER + 1], oz - s[CENTER + 2]
    A, B = dot(dx, dy, dz, dx, dy, dz), dot(Sx, Sy, Sz, dx, dy, dz)
    C = dot(Sx, Sy, Sz, Sx, Sy, Sz) - s[RADIUS2]
    disc = B * B - A * C
    q = -B - copysign(sqrt(maximum(disc, 0.0)), B)
    t1, t2 = q / A, C / q
    near, far = minimum(t1, t2), maximum(t1, t2)
    miss = (disc < 0) | (not_(isfinite(near)) & not_(isfinite(far)))
    return select(miss, INF, near), select(miss, INF, far)


@kernel
def first_root(near, far, t_min, t_max):
    """The first of two roots in (t_min, t_max), inf if neither is."""
    t = select(near > t_min, near, far)
    return select((t > t_min) & (t < t_max), t, INF)


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    near, far = roots(s, ox, oy, oz, dx, dy, dz)
    return first_root(near, far, t_min, t_max), 0


@kernel
def spans(s, pool, ox, oy, oz, dx, dy, dz):
    near, far = roots(s, ox, oy, oz, dx, dy, dz)
    return near, 0, far, 0


@kernel
def normals(s, pool, prim, x, y, z):
    """(P - center) / r: unit on the surface."""
    r = s[RADIUS]
    nx, ny, nz = (x - s[CENTER]) / r, (y - s[CENTER + 1]) / r, (z - s[CENTER + 2]) / r
    return nx, ny, nz, nx, ny, nz


@kernel
def uv(s, pool, prim, x, y, z):
    """Longitude around +y and latitude of the point's direction q from the centre."""
    r = s[RADIUS]
    qx, qy, qz = (x - s[CENTER]) / r, (y - s[CENTER + 1]) / r, (z - s[CENTER + 2]) / r
    return (0.5 + arctan2(qx, qz) / (2 * math.pi),
            0.5 + arcsin(minimum(maximum(qy, -1.0), 1.0)) / math.pi)


class Sphere(Shape):
    params = (Param("center", "vector", (0.0, 0.0, 0.0)), Param("radius", "number", 1.0, positive=True))
    kernels = ShapeKernels(hit, normals, uv, spans)

    __slots__ = ("row",)                 # scenes of a million spheres: only the row per sphere

    def __init__(self, center=(0.0, 0.0, 0.0), radius: float = 1.0):
        center, radius = np.asarray(center, dtype=float), float(radius)
        self.row = np.array([*center, radius, radius ** 2])

    @property
    def center(self) -> np.ndarray:
        return self.row[CENTER:CENTER + 3]

    @property
    def radius(self) -> float:
        return float(self.row[RADIUS])

    def bounds(self):
        return self.center - self.radius, self.center + self.radius

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls((0.3, -0.2, 0.1), 1.3)]
