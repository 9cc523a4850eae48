"""Triangles, alone or as a mesh's faces (notes 000 11.3.1, 004).

YAML: `triangle: {vertices: [a, b, c], normals: [na, nb, nc]}`; `normals` optional:
with them the triangle is smooth (normals interpolated from its corners).
The outward normal follows the vertex order by the right-hand rule (counter-clockwise
seen from the front). (u, v) are the barycentric coordinates (alpha, beta) of notes
000 11.3.1, or a mesh's interpolated vt.

A triangle is a row of the pool (its corner a, edges e1 = b - a, e2 = c - a, the face
normal e1 x e2, the corner normals and corner (u, v)); a Triangle owns one such row, a
Mesh (mesh.py) one per face. The shape's own row says where its rows start, whether
it is smooth and whether it has corner (u, v).
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import cross, cross3, dot, length3, unit3
from rtcli.shapes.base import POOL_WIDTH, Param, ParamError, Shape, ShapeKernels
from rtcli.kernels.variants import INF, isnan, kernel, minimum, not_, per_ray, select, sqrt, to_int

# a pool row: corner a, edges e1 and e2, face normal, corner normals na, nb, nc, corner (u, v)s
A, E1, E2, FACE, NA, NB, NC, UVA, UVB, UVC = 0, 3, 6, 9, 12, 15, 18, 21, 23, 25
# the shape's row: first pool row, smooth (1 or 0), has corner (u, v) (1 or 0), a mesh's BVH root
FIRST, SMOOTH, HAS_UV, ROOT = 0, 1, 2, 3


@kernel
def triangle_t(pool, j, ox, oy, oz, dx, dy, dz):
    """Solve o + t d = a + alpha e1 + beta e2 for triangle j by Cramer's rule (notes 000
    11.3.1): t where alpha >= 0, beta >= 0 and alpha + beta <= 1, else inf."""
    e1x, e1y, e1z = pool[j, E1], pool[j, E1 + 1], pool[j, E1 + 2]
    e2x, e2y, e2z = pool[j, E2], pool[j, E2 + 1], pool[j, E2 + 2]
    px, py, pz = cross(dx, dy, dz, e2x, e2y, e2z)
    det = dot(px, py, pz, e1x, e1y, e1z)
    inv = 1.0 / det
    sx, sy, sz = ox - pool[j, A], oy - pool[j, A + 1], oz - pool[j, A + 2]
    alpha = dot(sx, sy, sz, px, py, pz) * inv
    qx, qy, qz = cross(sx, sy, sz, e1x, e1y, e1z)
    beta = dot(dx, dy, dz, qx, qy, qz) * inv
    t = dot(qx, qy, qz, e2x, e2y, e2z) * inv
    return select((det != 0) & (alpha >= 0) & (beta >= 0) & (alpha + beta <= 1), t, INF)


@kernel
def barycentric(pool, j, x, y, z):
    """(alpha, beta) of the point (x, y, z) in the plane of triangle j (the weights of b and c)."""
    e1x, e1y, e1z = pool[j, E1], pool[j, E1 + 1], pool[j, E1 + 2]
    e2x, e2y, e2z = pool[j, E2], pool[j, E2 + 1], pool[j, E2 + 2]
    qx, qy, qz = x - pool[j, A], y - pool[j, A + 1], z - pool[j, A + 2]
    d00, d01, d11 = dot(e1x, e1y, e1z, e1x, e1y, e1z), dot(e1x, e1y, e1z, e2x, e2y, e2z), \
        dot(e2x, e2y, e2z, e2x, e2y, e2z)
    d20, d21 = dot(qx, qy, qz, e1x, e1y, e1z), dot(qx, qy, qz, e2x, e2y, e2z)
    den = d00 * d11 - d01 * d01
    return (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den


@kernel
def corners(pool, j, at, size, alpha, beta):
    """(1 - alpha - beta) c_a + alpha c_b + beta c_c for the corner values at pool[j, at:],
    each `size` long (component 0 of them; add to `at` for the others)."""
    return (1 - alpha - beta) * pool[j, at] + alpha * pool[j, at + size] + beta * pool[j, at + 2 * size]


@kernel
def below(pool, j, at, qx, qy, qz):
    """min(0, q . n) n, n the corner normal at pool[j, at:] and q the offset of a point from that
    corner: how far the point lies below the corner's tangent plane, along n (0 on or above it)."""
    nx, ny, nz = pool[j, at], pool[j, at + 1], pool[j, at + 2]
    h = minimum(dot(qx, qy, qz, nx, ny, nz), 0.0)
    return h * nx, h * ny, h * nz


@kernel
def terminator(s, pool, prim, x, y, z):
    """Hanika's shadow-terminator shift at the point (x, y, z) of a smooth face (Ray Tracing Gems
    II, ch. 4): the point projected onto each corner's tangent plane where it lies below it, the
    three blended by the barycentric weights, minus the point; (0, 0, 0) on a flat face
    (docs/scene-format.md, Shadow terminator)."""
    j = to_int(s[FIRST]) + prim
    if s[SMOOTH] == 0:
        return 0.0, 0.0, 0.0
    alpha, beta = barycentric(pool, j, x, y, z)
    gamma = 1 - alpha - beta
    ax, ay, az = pool[j, A], pool[j, A + 1], pool[j, A + 2]
    ux, uy, uz = below(pool, j, NA, x - ax, y - ay, z - az)
    vx, vy, vz = below(pool, j, NB, x - (ax + pool[j, E1]), y - (ay + pool[j, E1 + 1]), z - (az + pool[j, E1 + 2]))
    wx, wy, wz = below(pool, j, NC, x - (ax + pool[j, E2]), y - (ay + pool[j, E2 + 1]), z - (az + pool[j, E2 + 2]))
    return (-(gamma * ux + alpha * vx + beta * wx), -(gamma * uy + alpha * vy + beta * wy),
            -(gamma * uz + alpha * vz + beta * wz))


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    t = triangle_t(pool, to_int(s[FIRST]), ox, oy, oz, dx, dy, dz)
    return select((t > t_min) & (t < t_max), t, INF), 0


@kernel
def normals(s, pool, prim, x, y, z):
    """The face normal e1 x e2; smooth: the corner normals interpolated, or the face normal
    where they cancel."""
    j = to_int(s[FIRST]) + prim
    gx, gy, gz = pool[j, FACE], pool[j, FACE + 1], pool[j, FACE + 2]
    if s[SMOOTH] == 0:
        return gx, gy, gz, gx, gy, gz
    alpha, beta = barycentric(pool, j, x, y, z)
    nx, ny, nz = corners(pool, j, NA, 3, alpha, beta), corners(pool, j, NA + 1, 3, alpha, beta), \
        corners(pool, j, NA + 2, 3, alpha, beta)
    flat = not_(sqrt(dot(nx, ny, nz, nx, ny, nz)) > 0)
    return select(flat, gx, nx), select(flat, gy, ny), select(flat, gz, nz), gx, gy, gz


@kernel
def uv(s, pool, prim, x, y, z):
    """The corners' (u, v) interpolated where the face has them, else (alpha, beta)."""
    j = to_int(s[FIRST]) + prim
    alpha, beta = barycentric(pool, j, x, y, z)
    if s[HAS_UV] == 0:
        return alpha, beta
    u, v = corners(pool, j, UVA, 2, alpha, beta), corners(pool, j, UVA + 1, 2, alpha, beta)
    return select(isnan(u), alpha, u), select(isnan(v), beta, v)


@per_ray(inline=True)
def triangle_leaf(g, j, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A BVH leaf entry that is triangle j of g.pool: (t in (t_min, t_max) or inf, j)."""
    t = triangle_t(g.pool, j, ox, oy, oz, dx, dy, dz)
    return (t if t_min < t < t_max else INF), j


def degenerate(a, b, c):
    """Triangles whose corners are (nearly) collinear: |(b - a) x (c - a)| <= 1e-12 extent^2."""
    extent = np.max(np.maximum(np.maximum(a, b), c) - np.minimum(np.minimum(a, b), c), axis=-1)
    return length3(cross3(b - a, c - a)) <= 1e-12 * extent * extent


def triangle_rows(a, b, c, corner_normals=None, corner_uvs=None) -> np.ndarray:
    """(F, POOL_WIDTH) pool rows of triangles a, b, c (F, 3); corner normals (F, 3, 3) and
    corner (u, v)s (F, 3, 2) when given (NaN (u, v) for faces without)."""
    rows = np.zeros((len(a), POOL_WIDTH))
    e1, e2 = b - a, c - a
    rows[:, A:A + 3], rows[:, E1:E1 + 3], rows[:, E2:E2 + 3], rows[:, FACE:FACE + 3] = a, e1, e2, cross3(e1, e2)
    if corner_normals is not None:
        rows[:, NA:NA + 9] = corner_normals.reshape(-1, 9)
    rows[:, UVA:UVA + 6] = np.nan if corner_uvs is None else corner_uvs.reshape(-1, 6)
    return rows


class Triangle(Shape):
    params = (Param("vertices", "vectors", count=3), Param("normals", "vectors", None, count=3))
    kernels = ShapeKernels(hit, normals, uv)
    FIRST_COLUMN = FIRST

    def __init__(self, a, b, c, normals=None):
        self.a, self.b, self.c = (np.asarray(v, dtype=float) for v in (a, b, c))
        if degenerate(self.a, self.b, self.c):
            raise ParamError("vertices", "degenerate triangle (its vertices are collinear)")
        if normals is not None and np.any(np.linalg.norm(normals, axis=1) == 0):
            raise ParamError("normals", "a vertex normal must not be the zero vector")
        self.normals = None if normals is None else unit3(np.asarray(normals, dtype=float))
        corner_normals = None if normals is None else self.normals[None]
        self.pool = triangle_rows(self.a[None], self.b[None], self.c[None], corner_normals)
        self.row = np.array([0.0, float(normals is not None), 0.0, 0.0])

    @classmethod
    def from_values(cls, vertices, normals=None) -> "Triangle":
        return cls(*vertices, normals=normals)

    def bounds(self):
        v = np.array([self.a, self.b, self.c])
        return v.min(axis=0), v.max(axis=0)

    @classmethod
    def examples(cls) -> list:
        return [cls((1, 0, 0.5), (3, 0.5, 0), (1, 2, 1)),
                cls((0, 0, 0), (2, 0, 0), (0, 2, 0.5), normals=[[0.3, 0, 1], [0, -0.4, 1], [-0.2, 0.2, 1]])]
