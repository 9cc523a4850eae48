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
tube encloses no volume, so its spans are empty and a csg refuses it as a child.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.core.elementary import arctan2
from rtcli.core.vec import cross3, dot, unit3
from rtcli.shapes.base import Param, ParamError, Shape, ShapeKernels
from rtcli.kernels.variants import (
    INF,
    copysign,
    isfinite,
    kernel,
    select,
    sqrt,
)

# the row: base point, e1, e2, unit axis a, r, h, s0, s1, capped (1 or 0)
BASE, E1, E2, AXIS, R, H, S0, S1, CAPPED = 0, 3, 6, 9, 12, 13, 14, 15, 16


@kernel
def local(s, x, y, z, point):
    """(x, y, z) in the local frame (e1 / r, e2 / r, a / h) from base (a point) or not (a vector)."""
    if point:
        x, y, z = x - s[BASE], y - s[BASE + 1], z - s[BASE + 2]
    return (dot(x, y, z, s[E1], s[E1 + 1], s[E1 + 2]) / s[R], dot(x, y, z, s[E2], s[E2 + 1], s[E2 + 2]) / s[R],
            dot(x, y, z, s[AXIS], s[AXIS + 1], s[AXIS + 2]) / s[H])


@kernel
def wall(s, Sx, Sy, Sz, cx, cy, cz):
    """Both roots of A t^2 + 2B t + C = 0 for x^2 + y^2 = w(z)^2 with 0 <= z <= 1, else inf.

    A = cx^2 + cy^2 - m^2 cz^2, B = Sx cx + Sy cy - m w(Sz) cz, C = Sx^2 + Sy^2 - w(Sz)^2,
    m = s1 - s0; t = q/A and C/q with q = -B - sign(B) sqrt(B^2 - AC) (no cancellation,
    and a ray parallel to a cone's side, A = 0, keeps its one root C/q).
    """
    m = s[S1] - s[S0]
    w0 = s[S0] + m * Sz
    A = cx * cx + cy * cy - m * m * cz * cz
    B = Sx * cx + Sy * cy - m * w0 * cz
    C = Sx * Sx + Sy * Sy - w0 * w0
    disc = B * B - A * C
    q = -B - copysign(sqrt(select(disc > 0, disc, 0.0)), B)          # no root where disc < 0 (ok below)
    t1, t2 = q / A, C / q
    z1, z2 = Sz + t1 * cz, Sz + t2 * cz
    ok1 = (disc >= 0) & isfinite(t1) & (z1 >= 0) & (z1 <= 1)
    ok2 = (disc >= 0) & isfinite(t2) & (z2 >= 0) & (z2 <= 1)
    return select(ok1, t1, INF), select(ok2, t2, INF)


@kernel
def cap(s, Sx, Sy, Sz, cx, cy, cz, z_cap, radius):
    """The plane z = z_cap inside the disk x^2 + y^2 <= radius^2, else inf."""
    if s[CAPPED] == 0 or radius == 0:
        return INF
    t = (z_cap - Sz) / cz
    ok = isfinite(t)
    t0 = select(ok, t, 0.0)
    x, y = Sx + t0 * cx, Sy + t0 * cy
    return select(ok & (x * x + y * y <= radius * radius), t, INF)


@kernel
def candidates(s, ox, oy, oz, dx, dy, dz):
    """t of the wall's two roots, the base cap and the top cap (inf: none)."""
    Sx, Sy, Sz = local(s, ox, oy, oz, True)
    cx, cy, cz = local(s, dx, dy, dz, False)
    w1, w2 = wall(s, Sx, Sy, Sz, cx, cy, cz)
    return w1, w2, cap(s, Sx, Sy, Sz, cx, cy, cz, 0.0, s[S0]), cap(s, Sx, Sy, Sz, cx, cy, cz, 1.0, s[S1])


@kernel
def nearer(t, prim, best, best_prim, t_min, t_max):
    """(best, best_prim) lowered to (t, prim) where t is in (t_min, t_max) and below best."""
    take = (t > t_min) & (t < t_max) & (t < best)
    return select(take, t, best), select(take, prim, best_prim)


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """The nearest of the wall's roots (prim 0), the base (1) and the top (2); the first on ties."""
    w1, w2, base, top = candidates(s, ox, oy, oz, dx, dy, dz)
    t, prim = nearer(w1, 0, INF, 0, t_min, t_max)
    t, prim = nearer(w2, 0, t, prim, t_min, t_max)
    t, prim = nearer(base, 1, t, prim, t_min, t_max)
    return nearer(top, 2, t, prim, t_min, t_max)


@kernel
def spans(s, pool, ox, oy, oz, dx, dy, dz):
    """The solid is convex: one interval from the first to the last surface crossed (any sign
    of t); none for an open tube or where fewer than two crossings are found."""
    if s[CAPPED] == 0:
        return INF, 0, INF, 0
    w1, w2, base, top = candidates(s, ox, oy, oz, dx, dy, dz)
    found = (select(isfinite(w1), 1, 0) + select(isfinite(w2), 1, 0) + select(isfinite(base), 1, 0)
             + select(isfinite(top), 1, 0)) >= 2
    t_in, p_in = nearer(w1, 0, INF, 0, -INF, INF)
    t_in, p_in = nearer(w2, 0, t_in, p_in, -INF, INF)
    t_in, p_in = nearer(base, 1, t_in, p_in, -INF, INF)
    t_in, p_in = nearer(top, 2, t_in, p_in, -INF, INF)
    t_out, p_out = select(isfinite(w1), w1, -INF), 0
    later = isfinite(w2) & (w2 > t_out)
    t_out, p_out = select(later, w2, t_out), select(later, 0, p_out)
    later = isfinite(base) & (base > t_out)
    t_out, p_out = select(later, base, t_out), select(later, 1, p_out)
    later = isfinite(top) & (top > t_out)
    t_out, p_out = select(later, top, t_out), select(later, 2, p_out)
    return select(found, t_in, INF), p_in, select(found, t_out, INF), p_out


@kernel
def normals(s, pool, prim, x, y, z):
    """Wall: the gradient (x, y, -m w(z)) taken back by A^-T; caps: -a and +a; a cone's apex:
    along the axis."""
    qx, qy, qz = local(s, x, y, z, True)
    m = s[S1] - s[S0]
    w = m * (s[S0] + m * qz) / s[H]
    a, b = qx / s[R], qy / s[R]
    ax, ay, az = s[AXIS], s[AXIS + 1], s[AXIS + 2]
    nx, ny, nz = a * s[E1] + b * s[E2] - w * ax, a * s[E1 + 1] + b * s[E2 + 1] - w * ay, \
        a * s[E1 + 2] + b * s[E2 + 2] - w * az
    apex = dot(nx, ny, nz, nx, ny, nz) == 0
    sign = select(prim == 1, -1.0, 1.0)
    nx = select(prim == 0, select(apex, ax, nx), sign * ax)
    ny = select(prim == 0, select(apex, ay, ny), sign * ay)
    nz = select(prim == 0, select(apex, az, nz), sign * az)
    return nx, ny, nz, nx, ny, nz


@kernel
def uv(s, pool, prim, x, y, z):
    qx, qy, qz = local(s, x, y, z, True)
    u_side = (arctan2(qy, qx) / (2 * math.pi)) % 1.0
    radius = select(prim == 2, s[S1], s[S0])
    side = prim == 0
    return select(side, u_side, (qx / radius + 1) / 2), select(side, qz, (qy / radius + 1) / 2)


class Tapered(Shape):
    """A cylinder or cone between base and top (see the module docstring)."""

    kernels = ShapeKernels(hit, normals, uv, spans)

    def __init__(self, base, top, radius, top_radius, capped=True):
        self.base, self.top = np.asarray(base, dtype=float), np.asarray(top, dtype=float)
        if np.array_equal(self.base, self.top):
            raise ParamError("top", "must differ from base (the axis has zero length)")
        self.radius, self.top_radius, self.capped = float(radius), float(top_radius), bool(capped)
        axis = self.top - self.base
        self.h = float(np.sqrt(dot(*axis, *axis)))      # height
        self.a = axis / self.h                          # unit axis
        helper = np.array([0.0, 1, 0]) if abs(self.a[1]) < 0.9 else np.array([1.0, 0, 0])
        self.e1 = unit3(cross3(helper, self.a))         # +x when the axis is +z
        self.e2 = cross3(self.a, self.e1)
        self.r = max(self.radius, self.top_radius)
        self.s0, self.s1 = self.radius / self.r, self.top_radius / self.r
        self.row = np.array([*self.base, *self.e1, *self.e2, *self.a, self.r, self.h, self.s0, self.s1,
                             float(self.capped)])

    @property
    def solid(self) -> bool:
        return self.capped

    def bounds(self):
        """The two end disks' boxes: a disk of radius rho with axis a spans rho sqrt(1 - a_k^2)."""
        e = np.sqrt(np.maximum(0.0, 1 - self.a * self.a))
        ends = [self.base - self.radius * e, self.base + self.radius * e,
                self.top - self.top_radius * e, self.top + self.top_radius * e]
        return np.min(ends, axis=0), np.max(ends, axis=0)


class Cylinder(Tapered):
    """Right-circular cylinder; generic form x^2 + y^2 = 1, |z| <= 1, with caps at z = +-1.

    YAML: `cylinder: {base: [0, 0, -1], top: [0, 0, 1], radius: 1, capped: true}`;
    every key optional (defaults shown: the generic cylinder); radius > 0, base != top.
    """

    params = (Param("base", "vector", (0.0, 0.0, -1.0)), Param("top", "vector", (0.0, 0.0, 1.0)),
              Param("radius", "number", 1.0, positive=True), Param("capped", "boolean", True))

    def __init__(self, base=(0.0, 0.0, -1.0), top=(0.0, 0.0, 1.0), radius=1.0, capped=True):
        super().__init__(base, top, radius, radius, capped)

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls((0, 0, -1), (0.3, 1, 0.5), 0.7), cls(capped=False)]


class Cone(Tapered):
    """Cone, or a truncated cone; generic form x^2 + y^2 = (1 - z)^2, 0 <= z <= 1, base cap at z = 0.

    YAML: `cone: {base: [0, 0, 0], top: [0, 0, 1], radius: 1, top_radius: 0, capped: true}`;
    every key optional (defaults shown: the generic cone). radius is at base, top_radius at
    top (0: a point); both >= 0 and not both 0 (radius 0 gives a cone standing on its tip);
    base != top. A truncated cone (both radii > 0) has both caps.
    """

    params = (Param("base", "vector", (0.0, 0.0, 0.0)), Param("top", "vector", (0.0, 0.0, 1.0)),
              Param("radius", "number", 1.0, non_negative=True), Param("top_radius", "number", 0.0, non_negative=True),
              Param("capped", "boolean", True))

    def __init__(self, base=(0.0, 0.0, 0.0), top=(0.0, 0.0, 1.0), radius=1.0, top_radius=0.0, capped=True):
        if radius == 0 and top_radius == 0:
            raise ParamError(("top_radius", "radius"), "radius and top_radius must not both be 0")
        super().__init__(base, top, radius, top_radius, capped)

    @classmethod
    def examples(cls) -> list:
        return [cls(), cls((0, 0, 0), (0, 1, 0), 1.0, 0.3), cls((0, 0, 0), (0, 0, 1), 0.0, 0.6)]
