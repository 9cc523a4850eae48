"""Torus around the z axis, in the xy plane (notes 002: "for torus up to 4 hits").

    f(P) = (|P|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + y^2) = 0,   inside where f < 0.

YAML: `torus: {major: 1, minor: 0.25}`: R = major, the radius of the tube's centre
circle, and r = minor, the tube's radius; both optional (defaults shown), both > 0.
minor < major is not required: with minor >= major the quartic is a horn or spindle
torus (the tube passes through the z axis; for minor > major the surface also has an
inner lemon-shaped part, and "inside" is still f < 0).
prim is always 0 (one surface). (u, v): u = angle around z / 2 pi (0 on +x, toward +y),
v = angle around the tube / 2 pi (0 on the outer equator, 0.25 on top), both in [0, 1).

All rays are solved at once, without a loop per ray:
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
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import dot, length


def _largest_cubic_root(A, B, C):
    """Largest real root of z^3 + A z^2 + B z + C = 0 (Cardano / trigonometric), then Newton."""
    p, q = B - A * A / 3, (2 * A * A * A - 9 * A * B) / 27 + C     # z = w - A/3: w^3 + p w + q = 0
    D = (q / 2) ** 2 + (p / 3) ** 3
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.cbrt(-q / 2 - np.copysign(np.sqrt(np.maximum(D, 0)), q))
        w_one = np.where(u != 0, u - p / (3 * u), 0.0)                # D > 0: one real root
        cos3 = np.clip(3 * q / (2 * p) * np.sqrt(-3 / p), -1, 1)
        w_three = 2 * np.sqrt(np.maximum(-p / 3, 0)) * np.cos(np.arccos(cos3) / 3)
    z = np.where(D > 0, w_one, np.where(p < 0, w_three, w_one)) - A / 3
    for _ in range(2):
        g, dg = ((z + A) * z + B) * z + C, (3 * z + 2 * A) * z + B
        with np.errstate(divide="ignore", invalid="ignore"):
            step = g / dg
        z = np.where(np.isfinite(step) & (dg != 0), z - step, z)
    return np.maximum(z, 0)


def _quadratic(k, m):
    """Real roots of y^2 + k y + m = 0, inf where complex."""
    disc = k * k - 4 * m
    q = -(k + np.copysign(np.sqrt(np.maximum(disc, 0)), k)) / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        y1, y2 = q, np.where(q != 0, m / q, 0.0)
    real = disc >= 0
    return np.where(real, y1, np.inf), np.where(real, y2, np.inf)


def _depressed_quartic(a, b, e):
    """Real roots (m, 4) of y^4 + a y^2 + b y + e = 0 by Descartes' factorisation, inf where complex."""
    z = _largest_cubic_root(2 * a, a * a - 4 * e, -b * b)
    k, s = np.sqrt(z), a + z                            # m + n = a + z, n - m = b / k, m n = e
    with np.errstate(divide="ignore", invalid="ignore"):
        by_k = b / k
    by_e = np.copysign(np.sqrt(np.maximum(s * s - 4 * e, 0)), b)   # (n - m)^2 = s^2 - 4e
    dlt = np.where(z * np.abs(s) > 0.5 * by_e * by_e, by_k, by_e)   # the better-conditioned one
    dlt = np.where(np.isfinite(dlt), dlt, by_e)
    m, n = (s - dlt) / 2, (s + dlt) / 2
    return np.stack(_quadratic(k, m) + _quadratic(-k, n), axis=1)


class Torus:
    def __init__(self, major: float = 1.0, minor: float = 0.25):
        self.R, self.r = float(major), float(minor)

    @classmethod
    def from_params(cls, p) -> "Torus":
        return cls(p.number("major", 1.0, positive=True), p.number("minor", 0.25, positive=True))

    def _along(self, S0, c):
        """The quartic along each ray, exactly: f(S0 + y c) = g^2 - 4R^2 h with
        g = |c|^2 y^2 + 2 sigma y + G and h = gamma y^2 + 2 beta y + rho, where sigma = S0.c,
        G = |S0|^2 + R^2 - r^2, gamma = cx^2 + cy^2, beta = S0x cx + S0y cy, rho = S0x^2 + S0y^2."""
        (x, y), (cx, cy) = S0[:, :2].T, c[:, :2].T
        return (dot(c, c), dot(S0, c), dot(S0, S0) + self.R * self.R - self.r * self.r,
                cx * cx + cy * cy, x * cx + y * cy, x * x + y * y)

    def _f(self, coef, y):
        """f(S0 + y c) and df/dy."""
        cc, sigma, G, gamma, beta, rho = coef
        g = (cc * y + 2 * sigma) * y + G
        h = (gamma * y + 2 * beta) * y + rho
        four_R2 = 4 * self.R * self.R
        return g * g - four_R2 * h, 4 * g * (cc * y + sigma) - 2 * four_R2 * (gamma * y + beta)

    def _polish(self, coef, y, steps=3):
        """Newton on f(S0 + y c) for the real roots, a step kept only where it lowers |f|
        (at a double root, grazing, f' = 0)."""
        real = np.isfinite(y)
        rows = np.nonzero(real)[0]
        coef = tuple(k[rows] for k in coef)
        x = y[real]
        f, df = self._f(coef, x)
        for _ in range(steps):
            with np.errstate(divide="ignore", invalid="ignore"):
                x1 = x - f / df
            x1 = np.where(np.isfinite(x1), x1, x)
            f1, df1 = self._f(coef, x1)
            better = np.abs(f1) < np.abs(f)
            x, f, df = np.where(better, x1, x), np.where(better, f1, f), np.where(better, df1, df)
        y = y.copy()
        y[real] = x
        return y

    def _roots(self, o, d):
        """All real roots t (n, 4) of the quartic along S + d t, sorted, inf-padded."""
        L = length(d)
        c = d / L[:, None]
        s0 = -dot(o, c)
        S0 = o + s0[:, None] * c
        near = dot(S0, S0) <= (self.R + self.r) ** 2    # the bounding sphere
        t = np.full((len(o), 4), np.inf)
        if near.any():
            coef = self._along(S0[near], c[near])
            _, _, G, gamma, beta, rho = coef
            four_R2 = 4 * self.R * self.R               # the depressed quartic, taking |c| = 1, S0.c = 0
            a, b, e = 2 * G - four_R2 * gamma, -2 * four_R2 * beta, G * G - four_R2 * rho
            y = self._polish(coef, _depressed_quartic(a, b, e))
            t[near] = (s0[near, None] + y) / L[near, None]
        return np.sort(t, axis=1)

    def intersect(self, o, d, t_min, t_max):
        t = self._roots(o, d)
        t = np.where((t > np.reshape(t_min, (-1, 1))) & (t < np.reshape(t_max, (-1, 1))), t, np.inf)
        return np.min(t, axis=1), None

    def spans(self, o, d):
        """Up to two intervals: f > 0 far along the ray, so sorted roots enter, exit, enter, exit."""
        t = self._roots(o, d)
        zero = np.zeros((len(o), 2), dtype=np.int64)
        return t[:, 0::2], zero, t[:, 1::2], zero.copy()

    def normal(self, p, prim):
        """grad f / 4 = (|P|^2 + R^2 - r^2) P - 2 R^2 (x, y, 0) (notes 000 11.6)."""
        g = dot(p, p) + self.R * self.R - self.r * self.r
        n = g[:, None] * p
        n[:, :2] -= 2 * self.R * self.R * p[:, :2]
        return n

    def uv(self, p, prim):
        rho = np.sqrt(p[:, 0] * p[:, 0] + p[:, 1] * p[:, 1])
        u = np.arctan2(p[:, 1], p[:, 0]) / (2 * np.pi)
        v = np.arctan2(p[:, 2], rho - self.R) / (2 * np.pi)
        return np.stack([np.mod(u, 1.0), np.mod(v, 1.0)], axis=1)

    def bounds(self):
        ext = self.R + self.r
        return np.array([-ext, -ext, -self.r]), np.array([ext, ext, self.r])
