"""The shapes of the compiled path, one ray at a time (numba): hit(k, ray) and normal(k, point).

Each function does the floating-point operations of its numpy twin in
rtcli/shapes/ in the same order (sphere_roots' stable quadratic, Box's slab
test, the tapered cylinder's wall and caps), so both paths find the same t,
face and normal. Rays and points are in object space; `apply` takes them
there, and normals back, as transform.py does.

Object rows (packed by rtcli/fast/pack.py) start with the shape's parameters:
  SPHERE  cx cy cz r r^2
  PLANE   point(3) n(3) e1(3) e2(3)   (e1, e2: the (u, v) axes)
  BOX     lo(3) hi(3)
  TAPERED base(3) e1(3) e2(3) a(3) r h s0 s1 capped   (cylinder and cone)
  TRIANGLE a(3) e1(3) e2(3) face(3) na(3) nb(3) nc(3) smooth   (as a mesh's pool row, plus the flag)
  SQUARE  (none: z = 0, |x|, |y| <= 1)
  POLYGON v0(3) n(3) axes(2) count e1(3) e2(3)   (its vertices in the pool)
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rtcli.compiled.pack import BOX, PLANE, POLYGON, SPHERE, SQUARE, TAPERED, TRIANGLE

# How the compiled engine's functions are built (measured on whitted at 960x540, ns per pixel):
# - error_model="numpy": x / 0 gives inf or nan, as in the numpy core, instead of raising.
# - _nrt=False (numba's switch for reference counting): these functions only read arrays that
#   trace_rays' caller owns; counting references to each array argument on every call made the
#   whole render 2.3x slower. Only `entry` (trace_rays, which allocates) keeps counting.
# - inline="always" for the functions taking the scene's tuples or called in the innermost
#   loops: a call passes each array as several machine words (780 -> 255 ns per pixel), at the
#   price of a longer first compilation (about 30 s, then cached).
jit = njit(cache=True, error_model="numpy", _nrt=False)
inline = njit(cache=True, error_model="numpy", _nrt=False, inline="always")
entry = njit(cache=True, error_model="numpy")


@jit
def apply(row, at, x, y, z, w):
    """The 3x4 matrix stored row by row in row[at:at + 12] times (x, y, z, w) (w = 1 a point, 0 a vector)."""
    rx = x * row[at] + y * row[at + 1] + z * row[at + 2]
    ry = x * row[at + 4] + y * row[at + 5] + z * row[at + 6]
    rz = x * row[at + 8] + y * row[at + 9] + z * row[at + 10]
    if w:
        rx, ry, rz = rx + row[at + 3], ry + row[at + 7], rz + row[at + 11]
    return rx, ry, rz


@jit
def first_root(t_near, t_far, t_min, t_max):
    """nearest_root: the first root in (t_min, t_max), inf if neither is."""
    t = t_near if t_near > t_min else t_far
    return t if t_min < t < t_max else np.inf


@inline
def sphere(p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """sphere_roots + nearest_root for the sphere p = (cx, cy, cz, r, r^2)."""
    Sx, Sy, Sz = ox - p[0], oy - p[1], oz - p[2]
    A = dx * dx + dy * dy + dz * dz
    B = Sx * dx + Sy * dy + Sz * dz
    C = Sx * Sx + Sy * Sy + Sz * Sz - p[4]
    disc = B * B - A * C
    q = -B - math.copysign(math.sqrt(max(disc, 0.0)), B)
    t1, t2 = q / A, C / q
    near, far = min(t1, t2), max(t1, t2)
    if math.isnan(t1) or math.isnan(t2):             # np.minimum / np.maximum propagate NaN
        near = far = np.nan
    if disc < 0 or (not math.isfinite(near) and not math.isfinite(far)):
        return np.inf
    return first_root(near, far, t_min, t_max)


@inline
def plane(p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """lambda* = (point.n - o.n) / (d.n), inf when parallel or out of range."""
    denom = dx * p[3] + dy * p[4] + dz * p[5]
    t = ((p[0] * p[3] + p[1] * p[4] + p[2] * p[5]) - (ox * p[3] + oy * p[4] + oz * p[5])) / denom
    return t if denom != 0 and t_min < t < t_max else np.inf


@jit
def box(p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """Box._slabs + intersect: (t, face) with face 2k (min side) or 2k + 1 (max side) of axis k."""
    o, d = (ox, oy, oz), (dx, dy, dz)
    t_near, t_far, k_in, k_out = -np.inf, np.inf, 0, 0
    for k in range(3):
        if d[k] == 0:
            inside = p[k] <= o[k] <= p[3 + k]
            t1, t2 = (-np.inf, np.inf) if inside else (np.inf, -np.inf)
        else:
            a, b = (p[k] - o[k]) / d[k], (p[3 + k] - o[k]) / d[k]
            t1, t2 = min(a, b), max(a, b)
        if k == 0 or t1 > t_near:                    # argmax / argmin: the first axis on ties
            t_near, k_in = t1, k
        if k == 0 or t2 < t_far:
            t_far, k_out = t2, k
    front = t_near > t_min
    t = t_near if front else t_far
    face = 2 * k_in + (d[k_in] < 0) if front else 2 * k_out + (d[k_out] > 0)
    return (t if t_near <= t_far and t_min < t < t_max else np.inf), face


@jit
def local(p, x, y, z, point):
    """_Tapered._local: (x, y, z) in the frame (e1 / r, e2 / r, a / h) from base."""
    if point:
        x, y, z = x - p[0], y - p[1], z - p[2]
    return ((x * p[3] + y * p[4] + z * p[5]) / p[12], (x * p[6] + y * p[7] + z * p[8]) / p[12],
            (x * p[9] + y * p[10] + z * p[11]) / p[13])


@jit
def cap(p, S, c, z_cap, s):
    """_Tapered._cap: the plane z = z_cap inside the disk x^2 + y^2 <= s^2, else inf."""
    if p[16] == 0 or s == 0:
        return np.inf
    t = (z_cap - S[2]) / c[2]
    if not math.isfinite(t):
        return np.inf
    x, y = S[0] + t * c[0], S[1] + t * c[1]
    return t if x * x + y * y <= s * s else np.inf


@jit
def tapered(p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """_Tapered.intersect: the nearest of the wall's two roots, the base cap and the top cap."""
    S, c = local(p, ox, oy, oz, True), local(p, dx, dy, dz, False)
    s0, s1 = p[14], p[15]
    m = s1 - s0
    w0 = s0 + m * S[2]
    A = c[0] * c[0] + c[1] * c[1] - m * m * c[2] * c[2]
    B = S[0] * c[0] + S[1] * c[1] - m * w0 * c[2]
    C = S[0] * S[0] + S[1] * S[1] - w0 * w0
    disc = B * B - A * C
    q = -B - math.copysign(math.sqrt(max(disc, 0.0)), B)
    cands = (q / A, C / q, cap(p, S, c, 0.0, s0), cap(p, S, c, 1.0, s1))
    best, prim = np.inf, 0
    for j in range(4):
        t = cands[j]
        if j < 2:                                    # wall roots: 0 <= z <= 1
            z = S[2] + t * c[2]
            if not (disc >= 0 and math.isfinite(t) and 0 <= z <= 1):
                t = np.inf
        if t_min < t < t_max and t < best:
            best, prim = t, max(j - 1, 0)            # prim 0 wall, 1 base, 2 top
    return best, prim


@jit
def square(p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """Square.intersect: the plane z = 0 within |x| <= 1, |y| <= 1."""
    denom = dx * 0.0 + dy * 0.0 + dz * 1.0
    t = ((0.0 * 0.0 + 0.0 * 0.0 + 0.0 * 1.0) - (ox * 0.0 + oy * 0.0 + oz * 1.0)) / denom
    if not (denom != 0 and t_min < t < t_max):
        return np.inf
    return t if abs(ox + t * dx) <= 1 and abs(oy + t * dy) <= 1 else np.inf


@inline
def hit(kind, p, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """(t, prim) of one shape for an object-space ray, inf on a miss."""
    if kind == SPHERE:
        return sphere(p, ox, oy, oz, dx, dy, dz, t_min, t_max), 0
    if kind == PLANE:
        return plane(p, ox, oy, oz, dx, dy, dz, t_min, t_max), 0
    if kind == BOX:
        return box(p, ox, oy, oz, dx, dy, dz, t_min, t_max)
    if kind == TAPERED:
        return tapered(p, ox, oy, oz, dx, dy, dz, t_min, t_max)
    if kind == TRIANGLE:
        t = triangle(p[0:3], p[3:6], p[6:9], ox, oy, oz, dx, dy, dz)
        return (t if t_min < t < t_max else np.inf), 0
    return square(p, ox, oy, oz, dx, dy, dz, t_min, t_max), 0


@inline
def normal(kind, p, x, y, z, prim):
    """The outward (geometric) normal, not unit, at the object-space point (x, y, z)."""
    if kind == SPHERE:
        return (x - p[0]) / p[3], (y - p[1]) / p[3], (z - p[2]) / p[3]
    if kind == PLANE or kind == POLYGON:
        return p[3], p[4], p[5]
    if kind == TRIANGLE:
        return p[9], p[10], p[11]
    if kind == SQUARE:
        return 0.0, 0.0, 1.0
    if kind == BOX:
        sign = 1.0 if prim % 2 else -1.0
        k = prim // 2
        return (sign if k == 0 else 0.0), (sign if k == 1 else 0.0), (sign if k == 2 else 0.0)
    if prim == 1:
        return -p[9], -p[10], -p[11]
    if prim == 2:
        return p[9], p[10], p[11]
    q = local(p, x, y, z, True)
    m = p[15] - p[14]
    w = m * (p[14] + m * q[2]) / p[13]
    a, b = q[0] / p[12], q[1] / p[12]
    n = (a * p[3] + b * p[6] - w * p[9], a * p[4] + b * p[7] - w * p[10], a * p[5] + b * p[8] - w * p[11])
    if n[0] * n[0] + n[1] * n[1] + n[2] * n[2] == 0:                 # a cone's apex: along the axis
        return p[9], p[10], p[11]
    return n


@jit
def barycentric(t, x, y, z):
    """planar.barycentric: (alpha, beta) of (x, y, z) in the plane of the triangle row t = (a, e1, e2, ...)."""
    qx, qy, qz = x - t[0], y - t[1], z - t[2]
    d00 = t[3] * t[3] + t[4] * t[4] + t[5] * t[5]
    d01 = t[3] * t[6] + t[4] * t[7] + t[5] * t[8]
    d11 = t[6] * t[6] + t[7] * t[7] + t[8] * t[8]
    d20 = qx * t[3] + qy * t[4] + qz * t[5]
    d21 = qx * t[6] + qy * t[7] + qz * t[8]
    den = d00 * d11 - d01 * d01
    return (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den


@jit
def corners(t, at, size, alpha, beta, j):
    """Mesh._interpolate: component j of the corner values t[at:at + 3 size] (a, b, c, each `size` long)."""
    return (1 - alpha - beta) * t[at + j] + alpha * t[at + size + j] + beta * t[at + 2 * size + j]


@jit
def interpolated(t, x, y, z):
    """Smooth normal of the triangle row t = (a, e1, e2, face, na, nb, nc) at (x, y, z)."""
    alpha, beta = barycentric(t, x, y, z)
    return (corners(t, 12, 3, alpha, beta, 0), corners(t, 12, 3, alpha, beta, 1),
            corners(t, 12, 3, alpha, beta, 2))


@jit
def triangle(a, e1, e2, ox, oy, oz, dx, dy, dz):
    """t of the ray in the triangle a + alpha e1 + beta e2, or inf (planar.triangle_solve's operations)."""
    p0, p1, p2 = dy * e2[2] - dz * e2[1], dz * e2[0] - dx * e2[2], dx * e2[1] - dy * e2[0]
    det = p0 * e1[0] + p1 * e1[1] + p2 * e1[2]
    if det == 0.0:
        return np.inf
    inv = 1.0 / det
    s0, s1, s2 = ox - a[0], oy - a[1], oz - a[2]
    alpha = (s0 * p0 + s1 * p1 + s2 * p2) * inv
    q0, q1, q2 = s1 * e1[2] - s2 * e1[1], s2 * e1[0] - s0 * e1[2], s0 * e1[1] - s1 * e1[0]
    beta = (dx * q0 + dy * q1 + dz * q2) * inv
    t = (q0 * e2[0] + q1 * e2[1] + q2 * e2[2]) * inv
    return t if alpha >= 0.0 and beta >= 0.0 and alpha + beta <= 1.0 else np.inf
