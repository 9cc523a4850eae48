"""Affine transforms of points, vectors and normals (notes 000, 11.3.4 and 11.6.1).

A Transform keeps its 4x4 matrix `m` (world_from_object) and the inverse `m_inv`.
For the kernels it is packed as three 3x4 matrices in a row of 36 floats
(`Transform.packed`): world_from_object (WORLD), object_from_world (OBJECT), and the
inverse transpose A^-T that takes object-space normals to world space (NORMAL, its
4th column 0). Products are written out per component, so a row's result never
depends on how many rows share the batch; so are the matrices' products and inverses
(no BLAS or LAPACK, whose order of operations depends on the CPU), and rotations take
their sine and cosine from rtcli/core/elementary.py: a scene's transforms have the same
bits on every CPU.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.elementary import cos, sin
from rtcli.core.vec import cross3, dot3, length3, split, stack
from rtcli.kernels.variants import kernel

WORLD, OBJECT, NORMAL, PACKED = 0, 12, 24, 36        # offsets of the 3x4 matrices in Transform.packed


@kernel
def linear(m, at, x, y, z):
    """The 3x3 part of the 3x4 matrix m[at:at + 12] (row by row) times the vector (x, y, z)."""
    return (x * m[at] + y * m[at + 1] + z * m[at + 2],
            x * m[at + 4] + y * m[at + 5] + z * m[at + 6],
            x * m[at + 8] + y * m[at + 9] + z * m[at + 10])


@kernel
def affine(m, at, x, y, z):
    """The 3x4 matrix m[at:at + 12] times the point (x, y, z, 1)."""
    rx, ry, rz = linear(m, at, x, y, z)
    return rx + m[at + 3], ry + m[at + 7], rz + m[at + 11]


@kernel
def ray_to_object(m, at, ox, oy, oz, dx, dy, dz):
    """The ray o + t d taken into object space by the packed transform at m[at:] (notes 000
    11.3.4): the inverse transform of its start and direction; t keeps its meaning."""
    qx, qy, qz = affine(m, at + OBJECT, ox, oy, oz)
    ex, ey, ez = linear(m, at + OBJECT, dx, dy, dz)
    return qx, qy, qz, ex, ey, ez


@kernel
def normal_to_world(m, at, nx, ny, nz):
    """A^-T n: an object-space normal in world space (notes 000 11.6.1); not unit."""
    return linear(m, at + NORMAL, nx, ny, nz)


@dataclass(frozen=True)
class Transform:
    m: np.ndarray           # (4, 4) world_from_object, affine
    m_inv: np.ndarray       # (4, 4) its inverse

    @staticmethod
    def from_matrix(m: np.ndarray) -> "Transform":
        """Raises ValueError for a singular matrix."""
        m = np.asarray(m, dtype=float)
        a, b, c = m[:3, :3]
        det = float(dot3(a, cross3(b, c)))
        scale = max(np.abs(m[:3, :3]).max(), 1e-300) ** 3
        if not np.isfinite(det) or abs(det) <= 1e-12 * scale:
            raise ValueError("singular transform (determinant 0)")
        return Transform(m, affine_inverse(m))

    @staticmethod
    def identity() -> "Transform":
        return Transform(np.eye(4), np.eye(4))

    def then(self, other: "Transform") -> "Transform":
        """This transform followed by `other` (the YAML list order)."""
        return Transform(product(other.m, self.m), product(self.m_inv, other.m_inv))

    @property
    def inverse(self) -> "Transform":
        return Transform(self.m_inv, self.m)

    @property
    def packed(self) -> np.ndarray:
        """(36,) world_from_object, object_from_world and A^-T, each 3x4 row by row."""
        normal = np.zeros((3, 4))
        normal[:, :3] = self.m_inv[:3, :3].T
        return np.concatenate([self.m[:3].ravel(), self.m_inv[:3].ravel(), normal.ravel()])

    def point(self, p: np.ndarray) -> np.ndarray:
        return stack(*affine(self.packed, WORLD, *split(p)))

    def vector(self, v: np.ndarray) -> np.ndarray:
        return stack(*linear(self.packed, WORLD, *split(v)))

    def normal(self, n: np.ndarray) -> np.ndarray:
        """A^-T n (not normalized)."""
        return stack(*normal_to_world(self.packed, 0, *split(n)))


def product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The 4x4 matrix product a b, each entry summed over k = 0..3 in that order."""
    return sum(a[:, k:k + 1] * b[k:k + 1, :] for k in range(4))


def affine_inverse(m: np.ndarray) -> np.ndarray:
    """The inverse of [A t; 0 1]: [A^-1, -A^-1 t], A^-1 by Gauss-Jordan elimination with partial
    pivoting on [A | I], one row operation at a time (a scale's inverse is 1/s, rounded once)."""
    rows = np.hstack([m[:3, :3], np.eye(3)])
    for k in range(3):
        pivot = k + int(np.argmax(np.abs(rows[k:, k])))
        rows[[k, pivot]] = rows[[pivot, k]]
        rows[k] = rows[k] / rows[k, k]
        for i in range(3):
            if i != k:
                rows[i] = rows[i] - rows[i, k] * rows[k]
    inverse = np.eye(4)
    inverse[:3, :3] = rows[:, 3:]
    t = m[:3, 3]
    inverse[:3, 3] = -(inverse[:3, 0] * t[0] + inverse[:3, 1] * t[1] + inverse[:3, 2] * t[2])
    return inverse


def translate(t) -> Transform:
    m = np.eye(4)
    m[:3, 3] = t
    return Transform.from_matrix(m)


def scale(s) -> Transform:
    return Transform.from_matrix(np.diag([*np.broadcast_to(np.asarray(s, float), (3,)), 1.0]))


def rotate(axis, degrees: float) -> Transform:
    """Right-handed rotation about `axis` through the origin (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    n = float(length3(a))
    if n == 0:
        raise ValueError("rotation axis must not be zero")
    x, y, z = a / n
    th = np.radians(np.fmod(degrees, 360.0))                  # exact: sin and cos in their domain
    c, s = float(cos(th)), float(sin(th))
    C = 1 - c
    m = np.eye(4)
    m[:3, :3] = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                 [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                 [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]
    return Transform.from_matrix(m)


def bounds_of_box(t: Transform, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World-space bounds of an object-space box after the transform."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    p = t.point(corners)
    return p.min(axis=0), p.max(axis=0)


def outer_bounds(world_from_object: Transform | None, box):
    """The world box around an object-space box (lo, hi), or None for an unbounded shape."""
    if box is None or world_from_object is None:
        return box
    return bounds_of_box(world_from_object, *box)
