"""Planar polygon p1 ... pk, convex or not, inside by the even-odd rule (notes 000 11.3.2).

YAML: `polygon: {vertices: [p1, p2, ...]}` (at least 3, coplanar, not all on one
line). The outward normal follows the vertex order by the right-hand rule (Newell's
normal). A polygon that crosses itself, a bow tie, is filled by the even-odd rule
like any other; when its loops cancel Newell's normal, the plane's normal is the
largest cross product of two edges from the first vertex. (u, v) are planar
coordinates in the polygon's plane, from its first vertex.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.vec import cross3, dot3, unit3
from rtcli.shapes.base import POOL_WIDTH, Param, ParamError, Shape, ShapeKernels
from rtcli.shapes.plane import NORMAL, POINT, in_plane_axes, normals, plane_t, uv
from rtcli.kernels.variants import INF, kernel, select, to_int

# the row: a plane's (its first vertex, unit normal, in-plane (u, v) axes e1, e2: the plane's normals
# and uv kernels serve), then the two axes of the projection, the vertex count and the first pool
# row; the vertices are pool rows (x, y, z)
AXIS_I, AXIS_J, COUNT, FIRST = 12, 13, 14, 15


@kernel
def component(k, x, y, z):
    """Component k of (x, y, z) (k the same for every ray)."""
    if k == 0:
        return x
    if k == 1:
        return y
    return z


@kernel
def hit(s, pool, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """The plane's hit, then the even-odd rule: crossings of the sides by a ray in the plane
    from the point along +i of the projection onto the axes (i, j); odd is inside."""
    t = plane_t(s[POINT], s[POINT + 1], s[POINT + 2], s[NORMAL], s[NORMAL + 1], s[NORMAL + 2],
                ox, oy, oz, dx, dy, dz, t_min, t_max)
    i, j, first, count = to_int(s[AXIS_I]), to_int(s[AXIS_J]), to_int(s[FIRST]), to_int(s[COUNT])
    px = component(i, ox + t * dx, oy + t * dy, oz + t * dz)
    py = component(j, ox + t * dx, oy + t * dy, oz + t * dz)
    inside = False
    for r in range(count):
        ax, ay = pool[first + r, i], pool[first + r, j]
        bx, by = pool[first + (r + 1) % count, i], pool[first + (r + 1) % count, j]
        crosses = ((ay > py) != (by > py)) & (px < ax + (py - ay) * (bx - ax) / (by - ay))
        inside = inside != crosses
    return select(inside, t, INF), 0


class Polygon(Shape):
    params = (Param("vertices", "vectors", min_count=3),)
    kernels = ShapeKernels(hit, normals, uv)
    FIRST_COLUMN = FIRST

    def __init__(self, vertices):
        self.v = np.asarray(vertices, dtype=float)
        scale = max(np.ptp(self.v, axis=0).max(), 1e-300)
        normal = _plane_normal(self.v)
        if np.linalg.norm(normal) <= 1e-12 * scale * scale:
            raise ParamError("vertices", "degenerate polygon (its vertices lie on one line)")
        self.n = unit3(normal)
        if np.abs(dot3(self.v - self.v[0], self.n)).max() > 1e-6 * scale:
            raise ParamError("vertices", "polygon vertices are not coplanar")
        self.axes = [k for k in range(3) if k != int(np.argmax(np.abs(self.n)))]
        self.e1, self.e2 = in_plane_axes(self.n)
        self.row = np.array([*self.v[0], *self.n, *self.e1, *self.e2, *self.axes, len(self.v), 0.0])
        self.pool = np.zeros((len(self.v), POOL_WIDTH))
        self.pool[:, :3] = self.v

    def bounds(self):
        return self.v.min(axis=0), self.v.max(axis=0)

    @classmethod
    def examples(cls) -> list:
        star = np.radians(90 + 144 * np.arange(5))               # the pentagram {5/2}: crosses itself
        return [cls([[0, 0, 1], [2, 0, 1], [2, 1, 1], [1, 1, 1], [1, 2, 1], [0, 2, 1]]),
                cls(np.stack([np.cos(star), np.sin(star), 0.3 * np.cos(star)], axis=1)),
                cls([[0, 0, 0], [2, 1, 0.5], [2, 0, 0.5], [0, 1, 0]])]            # a bow tie


def _plane_normal(v: np.ndarray) -> np.ndarray:
    """Newell's normal (2 x area x normal), or where a self-crossing polygon's loops cancel it,
    the largest cross product of two edges from the first vertex (zero: all on one line)."""
    scale = max(np.ptp(v, axis=0).max(), 1e-300)
    newell = np.sum(cross3(v, np.roll(v, -1, axis=0)), axis=0)
    if np.linalg.norm(newell) > 1e-6 * scale * scale:
        return newell
    edges = v[1:] - v[0]
    crosses = cross3(edges[:, None], edges[None, :]).reshape(-1, 3)
    return crosses[np.argmax(np.linalg.norm(crosses, axis=1))]
