"""Sphere (notes 000 11.3.3, 002): |P - center|^2 = radius^2.

YAML: `sphere: {center: [0, 0, 0], radius: 1}`; both optional (the generic unit sphere).
(u, v): u the longitude around +y (0.5 faces +z), v the latitude, 0 at the south pole.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import dot


def sphere_roots(S, d, r2):
    """Roots of A t^2 + 2B t + C = 0, A = |d|^2, B = S.d, C = |S|^2 - r^2, S = o - center.

    The notes' t = (-B -+ sqrt(B^2 - AC)) / A, computed as q/A and C/q with
    q = -B - sign(B) sqrt(B^2 - AC), which avoids cancellation. (t_near, t_far), inf on a miss.
    """
    A, B, C = dot(d, d), dot(S, d), dot(S, S) - r2
    disc = B * B - A * C
    root = np.sqrt(np.maximum(disc, 0))
    q = -B - np.copysign(root, B)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = q / A, C / q
    t_near, t_far = np.minimum(t1, t2), np.maximum(t1, t2)
    miss = (disc < 0) | ~np.isfinite(t_near) & ~np.isfinite(t_far)
    return np.where(miss, np.inf, t_near), np.where(miss, np.inf, t_far)


def nearest_root(t_near, t_far, t_min, t_max):
    """The first root in (t_min, t_max), inf if neither is."""
    t = np.where(t_near > t_min, t_near, t_far)
    return np.where((t > t_min) & (t < t_max), t, np.inf)


def sphere_uv(q):
    """(u, v) of unit vectors q from the centre: longitude around +y, latitude from the south pole."""
    u = 0.5 + np.arctan2(q[:, 0], q[:, 2]) / (2 * np.pi)
    v = 0.5 + np.arcsin(np.clip(q[:, 1], -1, 1)) / np.pi
    return np.stack([u, v], axis=1)


class Sphere:
    def __init__(self, center=(0.0, 0.0, 0.0), radius: float = 1.0):
        self.center = np.asarray(center, dtype=float)
        self.radius = float(radius)

    @classmethod
    def from_params(cls, p) -> "Sphere":
        return cls(p.vector("center", (0, 0, 0)), p.number("radius", 1.0, positive=True))

    def _roots(self, o, d):
        return sphere_roots(o - self.center, d, self.radius ** 2)

    def intersect(self, o, d, t_min, t_max):
        return nearest_root(*self._roots(o, d), t_min, t_max), None

    def spans(self, o, d):
        t_near, t_far = self._roots(o, d)
        zero = np.zeros((len(o), 1), dtype=np.int64)
        return t_near[:, None], zero, t_far[:, None], zero

    def normal(self, p, prim):
        return (p - self.center) / self.radius

    def uv(self, p, prim):
        return sphere_uv((p - self.center) / self.radius)

    def bounds(self):
        return self.center - self.radius, self.center + self.radius
