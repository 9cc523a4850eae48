"""Infinite plane through `point` with outward `normal` (notes 000 11.3.1).

YAML: `plane: {point: [0, 0, 0], normal: [0, 1, 0]}`; both optional (the plane y = 0,
normal +y). (u, v) are planar coordinates in the plane along two unit vectors e1, e2
(for n = +y: u = x, v = -z). As a solid (a CSG child) it is the half-space behind
its normal, as POV-Ray's plane.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import cross3, dot, unit3
from rtcli.shapes.base import Param, ParamError, Shape, ShapeKernels
from rtcli.kernels.variants import INF, kernel, select

POINT, NORMAL, E1, E2 = 0, 3, 6, 9                    # the row: point, unit normal n, in-plane axes


@kernel
def plane_t(px, py, pz, nx, ny, nz, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """lambda* = (p1 - a).n / (d.n) (notes 000 11.3.1) for the plane through p1 with normal n;
    inf when parallel or out of (t_min, t_max)."""
    denom = dot(dx, dy, dz, nx, ny, nz)
    t = (dot(px, py, pz, nx, ny, nz) - dot(ox, oy, oz, nx, ny, nz)) / denom
    return select((denom != 0) & (t > t_min) & (t < t_max), t, INF)


@kernel
def planar_uv(s, at_point, at_axes, x, y, z):
    """(q.e1, q.e2) with q = (x, y, z) - the point at s[at_point]; e1, e2 at s[at_axes]."""
    qx, qy, qz = x - s[at_point], y - s[at_point + 1], z - s[at_point + 2]
    return dot(qx, qy, qz, s[at_axes], s[at_axes + 1], s[at_axes + 2]), \
        dot(qx, qy, qz, s[at_axes + 3], s[at_axes + 4], s[at_axes + 5])


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    return plane_t(s[POINT], s[POINT + 1], s[POINT + 2], s[NORMAL], s[NORMAL + 1], s[NORMAL + 2],
                   ox, oy, oz, dx, dy, dz, t_min, t_max), 0


@kernel
def spans(s, pool, ox, oy, oz, dx, dy, dz):
    """The half-space behind the normal: from -inf or the plane to the plane or +inf."""
    nx, ny, nz = s[NORMAL], s[NORMAL + 1], s[NORMAL + 2]
    denom = dot(dx, dy, dz, nx, ny, nz)
    dist = dot(ox - s[POINT], oy - s[POINT + 1], oz - s[POINT + 2], nx, ny, nz)
    t = -dist / denom
    inside_parallel = (denom == 0) & (dist <= 0)
    t_in = select(denom > 0, -INF, select(denom < 0, t, select(inside_parallel, -INF, INF)))
    t_out = select(denom > 0, t, INF)
    return t_in, 0, t_out, 0


@kernel
def normals(s, pool, prim, x, y, z):
    return s[NORMAL], s[NORMAL + 1], s[NORMAL + 2], s[NORMAL], s[NORMAL + 1], s[NORMAL + 2]


@kernel
def uv(s, pool, prim, x, y, z):
    return planar_uv(s, POINT, E1, x, y, z)


def in_plane_axes(n):
    """Two unit vectors spanning the plane with normal n; for n = +y they are +x and -z."""
    helper = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 0, 1.0])
    e2 = unit3(cross3(n, helper))
    return unit3(cross3(e2, n)), e2


class Plane(Shape):
    params = (Param("point", "vector", (0.0, 0.0, 0.0)), Param("normal", "vector", (0.0, 1.0, 0.0)))
    kernels = ShapeKernels(hit, normals, uv, spans)

    def __init__(self, point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0)):
        if not np.any(normal):
            raise ParamError("normal", "must not be the zero vector")
        self.point = np.asarray(point, dtype=float)
        self.n = unit3(np.asarray(normal, dtype=float))
        self.e1, self.e2 = in_plane_axes(self.n)
        self.row = np.concatenate([self.point, self.n, self.e1, self.e2])

    def bounds(self):
        return None

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls((1, 2, 3), (1, 1, -1))]
