"""The generic square z = 0, |x| <= 1, |y| <= 1, normal +z (notes 002).

YAML: `square: {}`; place it with `transform:`. (u, v) = ((x + 1)/2, (y + 1)/2).
"""

from __future__ import annotations

import numpy as np

from rtcli.shapes.base import Shape, ShapeKernels
from rtcli.kernels.variants import INF, kernel, select


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """The plane z = 0 at t = -oz / dz, inside |x| <= 1 and |y| <= 1."""
    t = -oz / dz
    inside = (abs(ox + t * dx) <= 1) & (abs(oy + t * dy) <= 1)
    return select((dz != 0) & (t > t_min) & (t < t_max) & inside, t, INF), 0


@kernel
def normals(s, pool, prim, x, y, z):
    return 0.0, 0.0, 1.0, 0.0, 0.0, 1.0


@kernel
def uv(s, pool, prim, x, y, z):
    return (x + 1) / 2, (y + 1) / 2


class Square(Shape):
    kernels = ShapeKernels(hit, normals, uv)

    def bounds(self):
        return np.array([-1.0, -1, 0]), np.array([1.0, 1, 0])

    @classmethod
    def examples(cls) -> list:
        return [cls()]
