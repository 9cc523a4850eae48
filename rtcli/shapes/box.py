"""Axis-aligned box by the slab test (notes 000 11.5's bounding boxes, 002's generic cube).

YAML: `box: {min: [-1, -1, -1], max: [1, 1, 1]}`; both optional (the generic
cube [-1, 1]^3); min < max in every component.

prim is the face hit: 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z (face 2k + 1 is the
max side of axis k). (u, v) are planar on each face, the box's extent mapped to
0..1: (y, z) on the x faces, (z, x) on the y faces, (x, y) on the z faces (the
next two axes in cyclic order, so u x v is +k).
"""

from __future__ import annotations

import numpy as np

from rtcli.shapes.base import Param, ParamError, Shape, ShapeKernels
from rtcli.kernels.variants import INF, kernel, not_, select

LO, HI = 0, 3                                         # the row: min corner, max corner


@kernel
def axis_slab(lo, hi, o, d):
    """Entry and exit t of the line through the slab lo <= P_k <= hi: (lo - S_k)/c_k and
    (hi - S_k)/c_k in order; a line parallel to it (c_k = 0) is inside for all t or none."""
    t_lo, t_hi = (lo - o) / d, (hi - o) / d
    within = (o >= lo) & (o <= hi)
    parallel, ordered = d == 0, t_lo < t_hi
    return (select(parallel, select(within, -INF, INF), select(ordered, t_lo, t_hi)),
            select(parallel, select(within, INF, -INF), select(ordered, t_hi, t_lo)))


@kernel
def slabs(s, ox, oy, oz, dx, dy, dz):
    """(t_near, face_in, t_far, face_out, miss): t_near the last entry over the three slabs,
    t_far the first exit (the first axis on ties); the ray misses when t_near > t_far.
    Moving down an axis enters by its max face."""
    t1x, t2x = axis_slab(s[LO], s[HI], ox, dx)
    t1y, t2y = axis_slab(s[LO + 1], s[HI + 1], oy, dy)
    t1z, t2z = axis_slab(s[LO + 2], s[HI + 2], oz, dz)
    later = t1y > t1x
    t_near, k_in, d_in = select(later, t1y, t1x), select(later, 1, 0), select(later, dy, dx)
    later = t1z > t_near
    t_near, k_in, d_in = select(later, t1z, t_near), select(later, 2, k_in), select(later, dz, d_in)
    sooner = t2y < t2x
    t_far, k_out, d_out = select(sooner, t2y, t2x), select(sooner, 1, 0), select(sooner, dy, dx)
    sooner = t2z < t_far
    t_far, k_out, d_out = select(sooner, t2z, t_far), select(sooner, 2, k_out), select(sooner, dz, d_out)
    face_in = 2 * k_in + select(d_in < 0, 1, 0)
    face_out = 2 * k_out + select(d_out > 0, 1, 0)
    return t_near, face_in, t_far, face_out, t_near > t_far


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    t_near, face_in, t_far, face_out, miss = slabs(s, ox, oy, oz, dx, dy, dz)
    front = t_near > t_min
    t = select(front, t_near, t_far)
    return select(not_(miss) & (t > t_min) & (t < t_max), t, INF), select(front, face_in, face_out)


@kernel
def spans(s, pool, ox, oy, oz, dx, dy, dz):
    """One interval [t_near, t_far] per ray (any sign of t), inf where the ray misses."""
    t_near, face_in, t_far, face_out, miss = slabs(s, ox, oy, oz, dx, dy, dz)
    return select(miss, INF, t_near), face_in, select(miss, INF, t_far), face_out


@kernel
def normals(s, pool, prim, x, y, z):
    """The face's outward axis: -1 or +1 along axis prim // 2."""
    sign, k = select(prim % 2 == 1, 1.0, -1.0), prim // 2
    nx, ny, nz = select(k == 0, sign, 0.0), select(k == 1, sign, 0.0), select(k == 2, sign, 0.0)
    return nx, ny, nz, nx, ny, nz


@kernel
def uv(s, pool, prim, x, y, z):
    qx = (x - s[LO]) / (s[HI] - s[LO])                  # 0..1 across the box
    qy = (y - s[LO + 1]) / (s[HI + 1] - s[LO + 1])
    qz = (z - s[LO + 2]) / (s[HI + 2] - s[LO + 2])
    k = prim // 2
    return select(k == 0, qy, select(k == 1, qz, qx)), select(k == 0, qz, select(k == 1, qx, qy))


def _fmt(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


class Box(Shape):
    params = (Param("min", "vector", (-1.0, -1.0, -1.0)), Param("max", "vector", (1.0, 1.0, 1.0)))
    kernels = ShapeKernels(hit, normals, uv, spans)

    def __init__(self, lo=(-1.0, -1.0, -1.0), hi=(1.0, 1.0, 1.0)):
        self.lo = np.asarray(lo, dtype=float)           # min corner
        self.hi = np.asarray(hi, dtype=float)           # max corner
        if not np.all(self.lo < self.hi):
            raise ParamError("max", f"must be > min in every component, got min {_fmt(self.lo)}, "
                                    f"max {_fmt(self.hi)}")
        self.row = np.concatenate([self.lo, self.hi])

    @classmethod
    def from_values(cls, **values) -> "Box":
        return cls(values["min"], values["max"])

    def bounds(self):
        return self.lo.copy(), self.hi.copy()

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls((-1, -0.5, -2), (1, 1, 0.5))]
