"""Flat shapes: plane, triangle, polygon (even-odd rule), square (notes 000 11.3.1-2, 004).

The outward normal of a triangle or polygon follows its vertex order by the
right-hand rule (counter-clockwise seen from the front).
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import cross, dot, length, normalize


def _plane_t(o, d, point, n, t_min, t_max):
    """lambda* = (p1 - a).n / (d.n) (notes 000 11.3.1); inf when parallel or out of range."""
    denom = dot(d, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (dot(point, n) - dot(o, n)) / denom
    return np.where((denom != 0) & (t > t_min) & (t < t_max), t, np.inf)


def _in_plane_basis(n):
    """Two unit vectors spanning the plane with normal n; for n = +y they are +x and -z."""
    helper = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 0, 1.0])
    e2 = normalize(cross(n, helper))
    return normalize(cross(e2, n)), e2


def triangle_solve(o, d, a, e1, e2):
    """Solve o + lambda d = a + alpha e1 + beta e2 by Cramer's rule (notes 000 11.3.1): (t, alpha, beta).

    Inside the triangle when alpha >= 0, beta >= 0 and alpha + beta <= 1.
    """
    pvec = cross(d, e2)
    det = dot(pvec, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        tvec = o - a
        alpha = dot(tvec, pvec) * inv
        qvec = cross(tvec, e1)
        beta = dot(d, qvec) * inv
        t = dot(qvec, e2) * inv
    return t, alpha, beta


def barycentric(q, e1, e2):
    """(alpha, beta) of the in-plane offsets q = p - a along the edges e1, e2."""
    d00, d01, d11 = dot(e1, e1), dot(e1, e2), dot(e2, e2)
    d20, d21 = dot(q, e1), dot(q, e2)
    den = d00 * d11 - d01 * d01
    return (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den


def degenerate(a, b, c):
    """Triangles whose corners are (nearly) collinear: |(b - a) x (c - a)| <= 1e-12 extent^2."""
    extent = np.max(np.maximum(np.maximum(a, b), c) - np.minimum(np.minimum(a, b), c), axis=-1)
    return length(cross(b - a, c - a)) <= 1e-12 * extent * extent


class Plane:
    """Infinite plane through `point` with outward `normal` (default y = 0, normal +y).

    YAML: `plane: {point: [0, 0, 0], normal: [0, 1, 0]}`. (u, v) are planar
    coordinates in the plane (for n = +y: u = x, v = -z).
    """

    def __init__(self, point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0)):
        self.point = np.asarray(point, dtype=float)
        self.n = normalize(np.asarray(normal, dtype=float))
        self.e1, self.e2 = _in_plane_basis(self.n)

    @classmethod
    def from_params(cls, p):
        normal = p.vector("normal", (0, 1, 0))
        if not np.any(normal):
            raise p.error("normal", "must not be the zero vector")
        return cls(p.vector("point", (0, 0, 0)), normal)

    def intersect(self, o, d, t_min, t_max):
        return _plane_t(o, d, self.point, self.n, t_min, t_max), None

    def spans(self, o, d):
        """The solid is the half-space behind the normal (as POV-Ray's plane)."""
        denom, dist = dot(d, self.n), dot(o - self.point, self.n)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -dist / denom
        inside_parallel = (denom == 0) & (dist <= 0)
        t_in = np.where(denom > 0, -np.inf, np.where(denom < 0, t, np.where(inside_parallel, -np.inf, np.inf)))
        t_out = np.where(denom > 0, t, np.where(denom < 0, np.inf, np.where(inside_parallel, np.inf, np.inf)))
        zero = np.zeros((len(o), 1), dtype=np.int64)
        return t_in[:, None], zero, t_out[:, None], zero

    def normal(self, p, prim):
        return np.broadcast_to(self.n, p.shape)

    def uv(self, p, prim):
        q = p - self.point
        return np.stack([dot(q, self.e1), dot(q, self.e2)], axis=1)

    def bounds(self):
        return None


class Triangle:
    """Triangle a, b, c; with `normals` [na, nb, nc] it is smooth (interpolated normals).

    YAML: `triangle: {vertices: [a, b, c], normals: [na, nb, nc]}`.
    (u, v) are the barycentric coordinates (alpha, beta) of notes 000 11.3.1.
    """

    def __init__(self, a, b, c, normals=None):
        self.a, self.b, self.c = (np.asarray(v, dtype=float) for v in (a, b, c))
        self.e1, self.e2 = self.b - self.a, self.c - self.a
        self.face = cross(self.e1, self.e2)
        self.normals = None if normals is None else normalize(np.asarray(normals, dtype=float))

    @classmethod
    def from_params(cls, p):
        v = p.vectors("vertices", count=3)
        normals = p.vectors("normals", count=3, default=None)
        if degenerate(*v):
            raise p.error("vertices", "degenerate triangle (its vertices are collinear)")
        if normals is not None and np.any(np.linalg.norm(normals, axis=1) == 0):
            raise p.error("normals", "a vertex normal must not be the zero vector")
        return cls(*v, normals=normals)

    def intersect(self, o, d, t_min, t_max):
        t, alpha, beta = triangle_solve(o, d, self.a, self.e1, self.e2)
        inside = (alpha >= 0) & (beta >= 0) & (alpha + beta <= 1)
        return np.where(inside & (t > t_min) & (t < t_max), t, np.inf), None

    def barycentric(self, p):
        """(alpha, beta) of points p in the triangle's plane."""
        return barycentric(p - self.a, self.e1, self.e2)

    def geometric_normal(self, p, prim):
        return np.broadcast_to(self.face, p.shape)

    def normal(self, p, prim):
        if self.normals is None:
            return self.geometric_normal(p, prim)
        alpha, beta = self.barycentric(p)
        na, nb, nc = self.normals
        n = (1 - alpha - beta)[:, None] * na + alpha[:, None] * nb + beta[:, None] * nc
        return np.where(length(n)[:, None] > 0, n, self.face)       # where the corners cancel: flat

    def uv(self, p, prim):
        return np.stack(self.barycentric(p), axis=1)

    def bounds(self):
        v = np.array([self.a, self.b, self.c])
        return v.min(axis=0), v.max(axis=0)


class Polygon:
    """Planar polygon p1 ... pk, convex or not, inside by the even-odd rule (notes 000 11.3.2).

    YAML: `polygon: {vertices: [p1, p2, ...]}` (at least 3, coplanar).
    (u, v) are planar coordinates in the polygon's plane, from its first vertex.
    """

    def __init__(self, vertices):
        self.v = np.asarray(vertices, dtype=float)
        newell = np.sum(cross(self.v, np.roll(self.v, -1, axis=0)), axis=0)   # 2 x area x normal
        self.n = normalize(newell)
        self.axes = [k for k in range(3) if k != int(np.argmax(np.abs(self.n)))]
        self.e1, self.e2 = _in_plane_basis(self.n)

    @classmethod
    def from_params(cls, p):
        v = p.vectors("vertices", min_count=3)
        scale = max(np.ptp(v, axis=0).max(), 1e-300)
        newell = np.sum(cross(v, np.roll(v, -1, axis=0)), axis=0)
        if np.linalg.norm(newell) <= 1e-12 * scale * scale:
            raise p.error("vertices", "degenerate polygon (zero area)")
        n = normalize(newell)
        if np.abs(dot(v - v[0], n)).max() > 1e-6 * scale:
            raise p.error("vertices", "polygon vertices are not coplanar")
        return cls(v)

    def intersect(self, o, d, t_min, t_max):
        t = _plane_t(o, d, self.v[0], self.n, t_min, t_max)
        hit = np.isfinite(t)
        inside = np.zeros(len(o), dtype=bool)
        if hit.any():
            p = o[hit] + t[hit, None] * d[hit]
            inside[hit] = self._inside(p)
        return np.where(inside, t, np.inf), None

    def _inside(self, p):
        """Crossings of a ray in the plane (+x of the projection) with the sides: odd = inside."""
        i, j = self.axes
        px, py = p[:, i:i + 1], p[:, j:j + 1]                     # (n, 1)
        ax, ay = self.v[:, i], self.v[:, j]                        # (k,)
        bx, by = np.roll(ax, -1), np.roll(ay, -1)
        straddles = (ay > py) != (by > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_cross = ax + (py - ay) * (bx - ax) / (by - ay)
        crossings = np.count_nonzero(straddles & (px < x_cross), axis=1)
        return crossings % 2 == 1

    def normal(self, p, prim):
        return np.broadcast_to(self.n, p.shape)

    def uv(self, p, prim):
        q = p - self.v[0]
        return np.stack([dot(q, self.e1), dot(q, self.e2)], axis=1)

    def bounds(self):
        return self.v.min(axis=0), self.v.max(axis=0)


class Square:
    """The generic square z = 0, |x| <= 1, |y| <= 1, normal +z (notes 002).

    YAML: `square: {}`; place it with `transform:`. (u, v) = ((x + 1)/2, (y + 1)/2).
    """

    N = np.array([0.0, 0.0, 1.0])

    @classmethod
    def from_params(cls, p):
        return cls()

    def intersect(self, o, d, t_min, t_max):
        t = _plane_t(o, d, np.zeros(3), self.N, t_min, t_max)
        with np.errstate(invalid="ignore"):
            p = o + np.where(np.isfinite(t), t, 0)[:, None] * d
        inside = (np.abs(p[:, 0]) <= 1) & (np.abs(p[:, 1]) <= 1)
        return np.where(inside, t, np.inf), None

    def normal(self, p, prim):
        return np.broadcast_to(self.N, p.shape)

    def uv(self, p, prim):
        return (p[:, :2] + 1) / 2

    def bounds(self):
        return np.array([-1.0, -1, 0]), np.array([1.0, 1, 0])
