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

_NORMALS = np.array([[-1.0, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]])
_UV_AXES = np.array([[1, 2], [2, 0], [0, 1]])          # (u, v) axes for faces of axis k


def _fmt(v) -> str:
    return "[" + ", ".join(f"{x:g}" for x in v) + "]"


class Box:
    def __init__(self, lo=(-1.0, -1.0, -1.0), hi=(1.0, 1.0, 1.0)):
        self.lo = np.asarray(lo, dtype=float)           # min corner
        self.hi = np.asarray(hi, dtype=float)           # max corner

    @classmethod
    def from_params(cls, p) -> "Box":
        lo, hi = p.vector("min", (-1, -1, -1)), p.vector("max", (1, 1, 1))
        if not np.all(lo < hi):
            raise p.error("max", f"must be > min in every component, got min {_fmt(lo)}, max {_fmt(hi)}")
        return cls(lo, hi)

    def _slabs(self, o, d):
        """Entry and exit of S + c t through the three slabs lo_k <= P_k <= hi_k.

        Per axis t = (lo_k - S_k)/c_k and (hi_k - S_k)/c_k; a ray parallel to a slab
        (c_k = 0) is inside it for all t or for none. t_near = max over the axes of
        the entries, t_far = min of the exits; the ray misses when t_near > t_far.
        Returns t_near, face_in, t_far, face_out, miss.
        """
        with np.errstate(divide="ignore", invalid="ignore"):
            t_lo, t_hi = (self.lo - o) / d, (self.hi - o) / d
        parallel, within = d == 0, (o >= self.lo) & (o <= self.hi)
        t1 = np.where(parallel, np.where(within, -np.inf, np.inf), np.minimum(t_lo, t_hi))
        t2 = np.where(parallel, np.where(within, np.inf, -np.inf), np.maximum(t_lo, t_hi))
        rows = np.arange(len(o))
        k_in, k_out = np.argmax(t1, axis=1), np.argmin(t2, axis=1)
        t_near, t_far = t1[rows, k_in], t2[rows, k_out]
        face_in = 2 * k_in + (d[rows, k_in] < 0)       # moving down an axis enters by its max face
        face_out = 2 * k_out + (d[rows, k_out] > 0)
        return t_near, face_in, t_far, face_out, t_near > t_far

    def intersect(self, o, d, t_min, t_max):
        t_near, face_in, t_far, face_out, miss = self._slabs(o, d)
        front = t_near > t_min
        t = np.where(front, t_near, t_far)
        t = np.where(~miss & (t > t_min) & (t < t_max), t, np.inf)
        return t, np.where(front, face_in, face_out)

    def spans(self, o, d):
        """One interval [t_near, t_far] per ray (any sign of t), inf where the ray misses."""
        t_near, face_in, t_far, face_out, miss = self._slabs(o, d)
        t_in, t_out = np.where(miss, np.inf, t_near), np.where(miss, np.inf, t_far)
        return t_in[:, None], face_in[:, None], t_out[:, None], face_out[:, None]

    def normal(self, p, prim):
        return _NORMALS[prim]

    def uv(self, p, prim):
        q = (p - self.lo) / (self.hi - self.lo)         # 0..1 across the box
        axes = _UV_AXES[prim // 2]
        rows = np.arange(len(p))
        return np.stack([q[rows, axes[:, 0]], q[rows, axes[:, 1]]], axis=1)

    def bounds(self):
        return self.lo.copy(), self.hi.copy()
