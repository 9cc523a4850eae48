"""Torus around the z axis, in the xy plane (notes 002: "for torus up to 4 hits").

    f(P) = (|P|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + y^2) = 0,   inside where f < 0.

YAML: `torus: {major: 1, minor: 0.25}`: R = major, the radius of the tube's centre
circle, and r = minor, the tube's radius; both optional (defaults shown), both > 0.
minor < major is not required: with minor >= major the quartic is a horn or spindle
torus (the tube passes through the z axis; for minor > major the surface also has an
inner lemon-shaped part, and "inside" is still f < 0).
prim is always 0 (one surface). (u, v): u = angle around z / 2 pi (0 on +x, toward +y),
v = angle around the tube / 2 pi (0 on the outer equator, 0.25 on top), both in [0, 1).

The roots, in closed form:
1. c = d / |d| and the ray's closest point to the centre S0 = S + s0 c, s0 = -S.c (the
   middle of its chord through the bounding sphere |P| = R + r); rays with |S0| > R + r
   miss. About S0 the quartic's coefficients stay of order R^4 however far S starts.
2. With P = S0 + y c (S0.c = 0, |c| = 1) the quartic is depressed:
   y^4 + a y^2 + b y + e = 0, G = |S0|^2 + R^2 - r^2, a = 2G - 4R^2 (cx^2 + cy^2),
   b = -8R^2 (S0x cx + S0y cy), e = G^2 - 4R^2 (S0x^2 + S0y^2).
3. Descartes: (y^2 + k y + m)(y^2 - k y + n) with z = k^2 the largest root of the
   resolvent cubic z^3 + 2a z^2 + (a^2 - 4e) z - b^2 = 0 (always >= 0).
4. Each real root is polished by Newton steps on f(S0 + y c) (its exact expansion, without
   the rounding of |c| = 1 and S0.c = 0); t = (s0 + y) / |d|.
The cubic's trigonometric solution uses arccos and cos, and its one-root form cbrt
(rtcli/core/elementary.py).
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.core.elementary import arccos, arctan2, cbrt, cos
from rtcli.core.vec import dot
from rtcli.shapes.base import Param, Shape, ShapeKernels
from rtcli.kernels.variants import (
    INF,
    copysign,
    isfinite,
    kernel,
    maximum,
    minimum,
    select,
    sqrt,
)

MAJOR, MINOR = 0, 1                                   # the row: R, r


@kernel
def newton_cubic(z, A, B, C):
    """One Newton step on z^3 + A z^2 + B z + C, kept where it is finite."""
    g, dg = ((z + A) * z + B) * z + C, (3 * z + 2 * A) * z + B
    step = g / dg
    return select(isfinite(step) & (dg != 0), z - step, z)


@kernel
def largest_cubic_root(A, B, C):
    """Largest real root of z^3 + A z^2 + B z + C = 0 (Cardano / trigonometric), then Newton."""
    p, q = B - A * A / 3, (2 * A * A * A - 9 * A * B) / 27 + C     # z = w - A/3: w^3 + p w + q = 0
    half_q, third_p = q / 2, p / 3
    D = half_q * half_q + third_p * third_p * third_p
    u = cbrt(-q / 2 - copysign(sqrt(maximum(D, 0.0)), q))
    w_one = select(u != 0, u - p / (3 * u), 0.0)                # D > 0: one real root
    cos3 = minimum(maximum(3 * q / (2 * p) * sqrt(-3 / p), -1.0), 1.0)
    w_three = 2 * sqrt(maximum(-p / 3, 0.0)) * cos(arccos(cos3) / 3)
    z = select(D > 0, w_one, select(p < 0, w_three, w_one)) - A / 3
    return maximum(newton_cubic(newton_cubic(z, A, B, C), A, B, C), 0.0)


@kernel
def quadratic(k, m):
    """Real roots of y^2 + k y + m = 0, inf where complex."""
    disc = k * k - 4 * m
    q = -(k + copysign(sqrt(maximum(disc, 0.0)), k)) / 2
    y2 = select(q != 0, m / q, 0.0)
    real = disc >= 0
    return select(real, q, INF), select(real, y2, INF)


@kernel
def depressed_quartic(a, b, e):
    """Real roots of y^4 + a y^2 + b y + e = 0 by Descartes' factorisation, inf where complex."""
    z = largest_cubic_root(2 * a, a * a - 4 * e, -b * b)
    k, s = sqrt(z), a + z                               # m + n = a + z, n - m = b / k, m n = e
    by_k = b / k
    by_e = copysign(sqrt(maximum(s * s - 4 * e, 0.0)), b)   # (n - m)^2 = s^2 - 4e
    dlt = select(z * abs(s) > 0.5 * by_e * by_e, by_k, by_e)   # the better-conditioned one
    dlt = select(isfinite(dlt), dlt, by_e)
    m, n = (s - dlt) / 2, (s + dlt) / 2
    y1, y2 = quadratic(k, m)
    y3, y4 = quadratic(-k, n)
    return y1, y2, y3, y4


@kernel
def along(cc, sigma, G, gamma, beta, rho, four_R2, y):
    """f(S0 + y c) and df/dy, exactly: g^2 - 4R^2 h with g = |c|^2 y^2 + 2 sigma y + G and
    h = gamma y^2 + 2 beta y + rho."""
    g = (cc * y + 2 * sigma) * y + G
    h = (gamma * y + 2 * beta) * y + rho
    return g * g - four_R2 * h, 4 * g * (cc * y + sigma) - 2 * four_R2 * (gamma * y + beta)


@kernel
def polish(cc, sigma, G, gamma, beta, rho, four_R2, y):
    """Three Newton steps on f(S0 + y c) from a real root y, each kept only where it lowers |f|
    (at a double root, grazing, f' = 0); inf (no root) stays inf."""
    x = select(isfinite(y), y, 0.0)
    f, df = along(cc, sigma, G, gamma, beta, rho, four_R2, x)
    for _ in range(3):
        x1 = x - f / df
        x1 = select(isfinite(x1), x1, x)
        f1, df1 = along(cc, sigma, G, gamma, beta, rho, four_R2, x1)
        better = abs(f1) < abs(f)
        x, f, df = select(better, x1, x), select(better, f1, f), select(better, df1, df)
    return select(isfinite(y), x, y)


@kernel
def order(a, b):
    return minimum(a, b), maximum(a, b)


@kernel
def roots(s, ox, oy, oz, dx, dy, dz):
    """All real roots t of the quartic along o + t d, sorted, inf where there are fewer than 4."""
    R, r = s[MAJOR], s[MINOR]
    L = sqrt(dot(dx, dy, dz, dx, dy, dz))
    cx, cy, cz = dx / L, dy / L, dz / L
    s0 = -dot(ox, oy, oz, cx, cy, cz)
    x, y, z = ox + s0 * cx, oy + s0 * cy, oz + s0 * cz
    near = dot(x, y, z, x, y, z) <= (R + r) * (R + r)   # the bounding sphere
    cc, sigma = dot(cx, cy, cz, cx, cy, cz), dot(x, y, z, cx, cy, cz)
    G = dot(x, y, z, x, y, z) + R * R - r * r
    gamma, beta, rho = cx * cx + cy * cy, x * cx + y * cy, x * x + y * y
    four_R2 = 4 * R * R                                 # the depressed quartic, taking |c| = 1, S0.c = 0
    y1, y2, y3, y4 = depressed_quartic(2 * G - four_R2 * gamma, -2 * four_R2 * beta, G * G - four_R2 * rho)
    t1 = select(near, (s0 + polish(cc, sigma, G, gamma, beta, rho, four_R2, y1)) / L, INF)
    t2 = select(near, (s0 + polish(cc, sigma, G, gamma, beta, rho, four_R2, y2)) / L, INF)
    t3 = select(near, (s0 + polish(cc, sigma, G, gamma, beta, rho, four_R2, y3)) / L, INF)
    t4 = select(near, (s0 + polish(cc, sigma, G, gamma, beta, rho, four_R2, y4)) / L, INF)
    t1, t2 = order(t1, t2)                              # a sorting network of four
    t3, t4 = order(t3, t4)
    t1, t3 = order(t1, t3)
    t2, t4 = order(t2, t4)
    t2, t3 = order(t2, t3)
    return t1, t2, t3, t4


@kernel
def within(t, t_min, t_max):
    return select((t > t_min) & (t < t_max), t, INF)


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    t1, t2, t3, t4 = roots(s, ox, oy, oz, dx, dy, dz)
    return minimum(minimum(within(t1, t_min, t_max), within(t2, t_min, t_max)),
                   minimum(within(t3, t_min, t_max), within(t4, t_min, t_max))), 0


@kernel
def spans(s, pool, ox, oy, oz, dx, dy, dz):
    """Up to two intervals: f > 0 far along the ray, so sorted roots enter, exit, enter, exit."""
    t1, t2, t3, t4 = roots(s, ox, oy, oz, dx, dy, dz)
    return t1, 0, t2, 0, t3, 0, t4, 0


@kernel
def normals(s, pool, prim, x, y, z):
    """grad f / 4 = (|P|^2 + R^2 - r^2) P - 2 R^2 (x, y, 0) (notes 000 11.6). Where it vanishes
    (a spindle torus's two points on the z axis, where the surface crosses itself) the normal is
    taken along the axis, away from the centre, as at a cone's apex."""
    R, r = s[MAJOR], s[MINOR]
    g = dot(x, y, z, x, y, z) + R * R - r * r
    two_R2 = 2 * R * R
    nx, ny, nz = g * x - two_R2 * x, g * y - two_R2 * y, g * z
    singular = dot(nx, ny, nz, nx, ny, nz) == 0
    nx, ny, nz = select(singular, 0.0, nx), select(singular, 0.0, ny), select(singular, copysign(1.0, z), nz)
    return nx, ny, nz, nx, ny, nz


@kernel
def uv(s, pool, prim, x, y, z):
    rho = sqrt(x * x + y * y)
    return (arctan2(y, x) / (2 * math.pi)) % 1.0, (arctan2(z, rho - s[MAJOR]) / (2 * math.pi)) % 1.0


class Torus(Shape):
    params = (Param("major", "number", 1.0, positive=True), Param("minor", "number", 0.25, positive=True))
    kernels = ShapeKernels(hit, normals, uv, spans)
    SPANS = 2

    def __init__(self, major: float = 1.0, minor: float = 0.25):
        self.R, self.r = float(major), float(minor)
        self.row = np.array([self.R, self.r])

    def bounds(self):
        ext = self.R + self.r
        return np.array([-ext, -ext, -self.r]), np.array([ext, ext, self.r])

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls(1.0, 0.3), cls(0.5, 0.7)]
