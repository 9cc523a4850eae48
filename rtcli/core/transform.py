"""Affine transforms on arrays of points, vectors and normals (notes 000, 11.3.4 and 11.6.1).

A Transform keeps its 4x4 matrix `m` and the inverse `m_inv`. Normals go through
the inverse transpose A^-T. Products are written out per component (not BLAS) so
a row's result never depends on how many rows share the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _apply(a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Rows of x (n, 3) times the 3x3 matrix a: a @ x_k for each k."""
    return x[:, 0:1] * a[:, 0] + x[:, 1:2] * a[:, 1] + x[:, 2:3] * a[:, 2]


@dataclass(frozen=True)
class Transform:
    m: np.ndarray           # (4, 4) world_from_object, affine
    m_inv: np.ndarray       # (4, 4) its inverse

    @staticmethod
    def from_matrix(m: np.ndarray) -> "Transform":
        """Raises ValueError for a singular matrix."""
        m = np.asarray(m, dtype=float)
        det = np.linalg.det(m[:3, :3])
        scale = max(np.abs(m[:3, :3]).max(), 1e-300) ** 3
        if not np.isfinite(det) or abs(det) <= 1e-12 * scale:
            raise ValueError("singular transform (determinant 0)")
        return Transform(m, np.linalg.inv(m))

    @staticmethod
    def identity() -> "Transform":
        return Transform(np.eye(4), np.eye(4))

    def then(self, other: "Transform") -> "Transform":
        """This transform followed by `other` (the YAML list order)."""
        return Transform(other.m @ self.m, self.m_inv @ other.m_inv)

    @property
    def inverse(self) -> "Transform":
        return Transform(self.m_inv, self.m)

    def point(self, p: np.ndarray) -> np.ndarray:
        return _apply(self.m[:3, :3], p) + self.m[:3, 3]

    def vector(self, v: np.ndarray) -> np.ndarray:
        return _apply(self.m[:3, :3], v)

    def normal(self, n: np.ndarray) -> np.ndarray:
        """A^-T n (not normalized)."""
        return _apply(self.m_inv[:3, :3].T, n)


def translate(t) -> Transform:
    m = np.eye(4)
    m[:3, 3] = t
    return Transform.from_matrix(m)


def scale(s) -> Transform:
    return Transform.from_matrix(np.diag([*np.broadcast_to(np.asarray(s, float), (3,)), 1.0]))


def rotate(axis, degrees: float) -> Transform:
    """Right-handed rotation about `axis` through the origin (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    n = np.linalg.norm(a)
    if n == 0:
        raise ValueError("rotation axis must not be zero")
    x, y, z = a / n
    th = np.radians(degrees)
    c, s, C = np.cos(th), np.sin(th), 1 - np.cos(th)
    m = np.eye(4)
    m[:3, :3] = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                 [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                 [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]
    return Transform(m, np.linalg.inv(m))


def bounds_of_box(t: Transform, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World-space bounds of an object-space box after the transform."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    p = t.point(corners)
    return p.min(axis=0), p.max(axis=0)


def ray_into(world_from_object: Transform | None, o: np.ndarray, d: np.ndarray):
    """The ray o + t d in object space: inverse-transformed start and direction (notes 000 11.3.4).

    t keeps its meaning. None means the object space is the world space.
    """
    if world_from_object is None:
        return o, d
    inv = world_from_object.inverse
    return inv.point(o), inv.vector(d)


def outer_bounds(world_from_object: Transform | None, box):
    """The world box around an object-space box (lo, hi), or None for an unbounded shape."""
    if box is None or world_from_object is None:
        return box
    return bounds_of_box(world_from_object, *box)
