"""(u, v) of the compiled shapes and image texture lookups, one point at a time (numba).

Each uv is its numpy shape's uv() in the same operations (sphere_uv, Box.uv,
_Tapered.uv, ...), and `image` is textures.ImageTexture.color: bilinear between
texel centres, tiled or clamped.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.compiled.pack import BOX, MESH, PLANE, POLYGON, SPHERE, SQUARE, TAPERED
from rtcli.compiled.shapes import barycentric, corners, jit, local


@jit
def planar(x, y, z, at_point, at_axes, p):
    """(q.e1, q.e2) with q = (x, y, z) - the point at p[at_point], e1 and e2 at p[at_axes]."""
    qx, qy, qz = x - p[at_point], y - p[at_point + 1], z - p[at_point + 2]
    e = at_axes
    return qx * p[e] + qy * p[e + 1] + qz * p[e + 2], qx * p[e + 3] + qy * p[e + 4] + qz * p[e + 5]


@jit
def tapered_uv(p, x, y, z, prim):
    """_Tapered.uv: the angle around the axis and the height on the side; planar on a cap."""
    q = local(p, x, y, z, True)
    if prim == 0:
        return (math.atan2(q[1], q[0]) / (2 * np.pi)) % 1.0, q[2]
    s = p[15] if prim == 2 else p[14]
    return (q[0] / s + 1) / 2, (q[1] / s + 1) / 2


@jit
def box_uv(p, x, y, z, prim):
    """Box.uv: the box's extent mapped to 0..1 along the face's two next axes in cyclic order."""
    q = ((x - p[0]) / (p[3] - p[0]), (y - p[1]) / (p[4] - p[1]), (z - p[2]) / (p[5] - p[2]))
    k = prim // 2
    return q[(k + 1) % 3], q[(k + 2) % 3]


@jit
def uv(kind, p, tri, prim, x, y, z):
    """(u, v) at the object-space point (x, y, z) of a shape with row p; tri: a mesh's triangle row."""
    if kind == SPHERE:
        qx, qy, qz = (x - p[0]) / p[3], (y - p[1]) / p[3], (z - p[2]) / p[3]
        return 0.5 + math.atan2(qx, qz) / (2 * np.pi), 0.5 + math.asin(min(max(qy, -1.0), 1.0)) / np.pi
    if kind == PLANE:
        return planar(x, y, z, 0, 6, p)
    if kind == POLYGON:
        return planar(x, y, z, 0, 9, p)
    if kind == BOX:
        return box_uv(p, x, y, z, prim)
    if kind == TAPERED:
        return tapered_uv(p, x, y, z, prim)
    if kind == SQUARE:
        return (x + 1) / 2, (y + 1) / 2
    alpha, beta = barycentric(tri, x, y, z)
    if kind == MESH:                                 # the file's vt where the face has them
        u, v = corners(tri, 21, 2, alpha, beta, 0), corners(tri, 21, 2, alpha, beta, 1)
        return (alpha if math.isnan(u) else u), (beta if math.isnan(v) else v)
    return alpha, beta


@jit
def wrap(k, n, repeat):
    """A texel index: modulo n when tiling, else clamped to 0 .. n - 1."""
    return k % n if repeat else min(max(k, 0), n - 1)


@jit
def image(texels, c, u, v):
    """textures.ImageTexture.color at (u, v); c = (kind, _, ..., offset, width, height, repeat) at 8..11."""
    at, w, h, repeat = int(c[8]), int(c[9]), int(c[10]), c[11] != 0
    if repeat:
        u, v = u - np.floor(u), v - np.floor(v)
    x = min(max(u, 0.0), 1.0) * w - 0.5                # continuous texel coordinates
    y = (1 - min(max(v, 0.0), 1.0)) * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    xa, xb = wrap(int(x0), w, repeat), wrap(int(x0) + 1, w, repeat)
    ya, yb = wrap(int(y0), h, repeat), wrap(int(y0) + 1, h, repeat)
    rows = (at + ya * w, at + yb * w)
    return (bilinear(texels, rows, xa, xb, fx, fy, 0), bilinear(texels, rows, xa, xb, fx, fy, 1),
            bilinear(texels, rows, xa, xb, fx, fy, 2))


@jit
def bilinear(texels, rows, xa, xb, fx, fy, j):
    """Channel j between the four texels (top and bottom row, columns xa and xb)."""
    top = texels[rows[0] + xa, j] * (1 - fx) + texels[rows[0] + xb, j] * fx
    bottom = texels[rows[1] + xa, j] * (1 - fx) + texels[rows[1] + xb, j] * fx
    return top * (1 - fy) + bottom * fy
