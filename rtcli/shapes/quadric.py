"""Cylinders and cones (notes 000 11.3.5; 002: "cylinder cap, base and side are 3 different surfaces").

Both are one shape, a tapered cylinder in a local frame q = (x, y, z): the wall
x^2 + y^2 = w(z)^2, w(z) = s0 + (s1 - s0) z, for 0 <= z <= 1 (the "quadratic
wall", then the test on z), the base cap z = 0 with x^2 + y^2 <= s0^2 and the
top cap z = 1 with x^2 + y^2 <= s1^2. The local frame is a rigid motion and a
scale of object space:
    q = ((P - base).e1 / r, (P - base).e2 / r, (P - base).a / h),
a the unit axis from base to top, h its length, (e1, e2, a) right-handed,
r = max(radius, top_radius), s0 = radius / r, s1 = top_radius / r. t is the same
in both spaces, and normals come back by the transpose of this map (A^-T of
notes 000 11.6.1). For the generic forms the map is z -> (z + 1)/2 (cylinder)
or the identity (cone: x^2 + y^2 = (1 - z)^2).

prim: 0 the side, 1 the base cap, 2 the top cap.
(u, v): on the side u = angle around the axis / 2 pi in [0, 1) (0 along e1,
which is +x for an axis along +z), v = height fraction, 0 at base, 1 at top;
on a cap, planar: u = (x/s + 1)/2, v = (y/s + 1)/2 along (e1, e2), s the cap's
radius, so the cap's bounding square is [0, 1]^2.
`capped: false` leaves an open tube (no caps; its inside is visible). An open
tube encloses no volume, so its spans() are empty and a csg refuses it as a child.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import cross, dot, normalize

_PRIM = np.array([0, 0, 1, 2])                          # candidates: wall root 1, 2, base, top


class _Tapered:
    def __init__(self, base, top, radius, top_radius, capped=True):
        self.base, self.top = np.asarray(base, dtype=float), np.asarray(top, dtype=float)
        self.radius, self.top_radius, self.capped = float(radius), float(top_radius), bool(capped)
        axis = self.top - self.base
        self.h = float(np.sqrt(dot(axis, axis)))        # height
        self.a = axis / self.h                          # unit axis
        helper = np.array([0.0, 1, 0]) if abs(self.a[1]) < 0.9 else np.array([1.0, 0, 0])
        self.e1 = normalize(cross(helper, self.a))      # +x when the axis is +z
        self.e2 = cross(self.a, self.e1)
        self.r = max(self.radius, self.top_radius)
        self.s0, self.s1 = self.radius / self.r, self.top_radius / self.r

    def _local(self, v, point=True):
        """Points (or vectors) in the local frame."""
        q = v - self.base if point else v
        return np.stack([dot(q, self.e1) / self.r, dot(q, self.e2) / self.r, dot(q, self.a) / self.h], axis=1)

    def _wall(self, S, c):
        """Roots of A t^2 + 2B t + C = 0 for x^2 + y^2 = w(z)^2 with 0 <= z <= 1, else inf.

        A = cx^2 + cy^2 - m^2 cz^2, B = Sx cx + Sy cy - m w(Sz) cz, C = Sx^2 + Sy^2 - w(Sz)^2,
        m = s1 - s0; t = q/A and C/q with q = -B - sign(B) sqrt(B^2 - AC) (no cancellation,
        and a ray parallel to a cone's side, A = 0, keeps its one root C/q).
        """
        m = self.s1 - self.s0
        w0 = self.s0 + m * S[:, 2]
        A = c[:, 0] * c[:, 0] + c[:, 1] * c[:, 1] - m * m * c[:, 2] * c[:, 2]
        B = S[:, 0] * c[:, 0] + S[:, 1] * c[:, 1] - m * w0 * c[:, 2]
        C = S[:, 0] * S[:, 0] + S[:, 1] * S[:, 1] - w0 * w0
        disc = B * B - A * C
        q = -B - np.copysign(np.sqrt(np.maximum(disc, 0)), B)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.stack([q / A, C / q], axis=1)
            z = S[:, 2:3] + t * c[:, 2:3]
        ok = (disc >= 0)[:, None] & np.isfinite(t) & (z >= 0) & (z <= 1)
        return np.where(ok, t, np.inf)

    def _cap(self, S, c, z_cap, s):
        """Hit of the plane z = z_cap inside the disk x^2 + y^2 <= s^2, else inf."""
        if not self.capped or s == 0:
            return np.full(len(S), np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (z_cap - S[:, 2]) / c[:, 2]
        ok = np.isfinite(t)
        t0 = np.where(ok, t, 0)
        x, y = S[:, 0] + t0 * c[:, 0], S[:, 1] + t0 * c[:, 1]
        return np.where(ok & (x * x + y * y <= s * s), t, np.inf)

    def _candidates(self, o, d):
        """(n, 4) t of the wall's two roots, the base cap and the top cap (inf: none)."""
        S, c = self._local(o), self._local(d, point=False)
        return np.concatenate([self._wall(S, c), self._cap(S, c, 0.0, self.s0)[:, None],
                               self._cap(S, c, 1.0, self.s1)[:, None]], axis=1)

    def intersect(self, o, d, t_min, t_max):
        t = self._candidates(o, d)
        t = np.where((t > np.reshape(t_min, (-1, 1))) & (t < np.reshape(t_max, (-1, 1))), t, np.inf)
        k = np.argmin(t, axis=1)
        return t[np.arange(len(t)), k], _PRIM[k]

    def spans(self, o, d):
        """The solid is convex: one interval from the first to the last surface crossed
        (any sign of t); none for an open tube or where fewer than two crossings are found."""
        n = len(o)
        if not self.capped:
            none = np.full((n, 1), np.inf)
            return none, np.zeros((n, 1), dtype=np.int64), none.copy(), np.zeros((n, 1), dtype=np.int64)
        t = self._candidates(o, d)
        rows, found = np.arange(n), np.count_nonzero(np.isfinite(t), axis=1) >= 2
        k_in, k_out = np.argmin(t, axis=1), np.argmax(np.where(np.isfinite(t), t, -np.inf), axis=1)
        t_in = np.where(found, t[rows, k_in], np.inf)
        t_out = np.where(found, t[rows, k_out], np.inf)
        return t_in[:, None], _PRIM[k_in][:, None], t_out[:, None], _PRIM[k_out][:, None]

    def normal(self, p, prim):
        """Wall: the gradient (x, y, -m w(z)) taken back by A^-T; caps: -a and +a."""
        q = self._local(p)
        m = self.s1 - self.s0
        w = self.s0 + m * q[:, 2]
        n = (q[:, 0:1] / self.r) * self.e1 + (q[:, 1:2] / self.r) * self.e2 \
            - (m * w / self.h)[:, None] * self.a
        n = np.where((dot(n, n) == 0)[:, None], self.a, n)      # a cone's apex: along the axis
        prim = np.asarray(prim)[:, None]
        return np.where(prim == 1, -self.a, np.where(prim == 2, self.a, n))

    def uv(self, p, prim):
        q = self._local(p)
        u_side = np.mod(np.arctan2(q[:, 1], q[:, 0]) / (2 * np.pi), 1.0)
        s = np.where(prim == 2, self.s1, self.s0)
        with np.errstate(divide="ignore", invalid="ignore"):
            u_cap, v_cap = (q[:, 0] / s + 1) / 2, (q[:, 1] / s + 1) / 2
        side = prim == 0
        return np.stack([np.where(side, u_side, u_cap), np.where(side, q[:, 2], v_cap)], axis=1)

    def bounds(self):
        """The two end disks' boxes: a disk of radius rho with axis a spans rho sqrt(1 - a_k^2)."""
        e = np.sqrt(np.maximum(0.0, 1 - self.a * self.a))
        ends = [self.base - self.radius * e, self.base + self.radius * e,
                self.top - self.top_radius * e, self.top + self.top_radius * e]
        return np.min(ends, axis=0), np.max(ends, axis=0)


def _axis(p, base_default, top_default):
    """base and top from p; they must differ."""
    base, top = p.vector("base", base_default), p.vector("top", top_default)
    if np.array_equal(base, top):
        raise p.error("top", "must differ from base (the axis has zero length)")
    return base, top


class Cylinder(_Tapered):
    """Right-circular cylinder; generic form x^2 + y^2 = 1, |z| <= 1, with caps at z = +-1.

    YAML: `cylinder: {base: [0, 0, -1], top: [0, 0, 1], radius: 1, capped: true}`;
    every key optional (defaults shown: the generic cylinder); radius > 0, base != top.
    """

    def __init__(self, base=(0.0, 0.0, -1.0), top=(0.0, 0.0, 1.0), radius=1.0, capped=True):
        super().__init__(base, top, radius, radius, capped)

    @classmethod
    def from_params(cls, p) -> "Cylinder":
        base, top = _axis(p, (0, 0, -1), (0, 0, 1))
        return cls(base, top, p.number("radius", 1.0, positive=True), p.boolean("capped", True))


class Cone(_Tapered):
    """Cone, or a truncated cone; generic form x^2 + y^2 = (1 - z)^2, 0 <= z <= 1, base cap at z = 0.

    YAML: `cone: {base: [0, 0, 0], top: [0, 0, 1], radius: 1, top_radius: 0, capped: true}`;
    every key optional (defaults shown: the generic cone). radius is at base, top_radius at
    top (0: a point); both >= 0 and not both 0 (radius 0 gives a cone standing on its tip);
    base != top. A truncated cone (both radii > 0) has both caps.
    """

    def __init__(self, base=(0.0, 0.0, 0.0), top=(0.0, 0.0, 1.0), radius=1.0, top_radius=0.0, capped=True):
        super().__init__(base, top, radius, top_radius, capped)

    @classmethod
    def from_params(cls, p) -> "Cone":
        base, top = _axis(p, (0, 0, 0), (0, 0, 1))
        radius = p.number("radius", 1.0, non_negative=True)
        top_radius = p.number("top_radius", 0.0, non_negative=True)
        if radius == 0 and top_radius == 0:
            key = "top_radius" if p.has("top_radius") else "radius"
            raise p.error(key, "radius and top_radius must not both be 0")
        return cls(base, top, radius, top_radius, p.boolean("capped", True))
