"""What every shape is: plain parameters, a row of floats, and kernels written once.

A shape class holds its parameters (built from plain values: numbers, vectors,
arrays) and says, as data, which YAML keys give them (`params`; the scene-file
builder reads them). Its geometry is computed by kernels (rtcli/kernels/variants.py) that
both engines call, over components in object space:

    hit(row, pool, ox, oy, oz, dx, dy, dz, t_min, t_max) -> (t, prim)
        the nearest root with t_min < t < t_max, inf where there is none; prim says
        which surface was hit (a box's face, a cylinder's cap; 0 for one surface)
    normals(row, pool, prim, x, y, z) -> (nx, ny, nz, gx, gy, gz)
        the outward shading and geometric normals at an object-space hit point, any
        length (they differ only for smooth triangles)
    uv(row, pool, prim, x, y, z) -> (u, v)      texture coordinates at the point
    spans(row, pool, ox, oy, oz, dx, dy, dz) -> (t_in, prim_in, t_out, prim_out) * SPANS
        the intervals of the line inside a solid, for CSG (any sign of t; inf, inf where
        there is no interval); only solids have it

`row` is the shape's parameters as floats (`Shape.row`), `pool` the rows it owns in a
shared table (a polygon's vertices, a mesh's triangles; `Shape.pool`), found from
row[FIRST] when the shape has any. A shape whose `kernels.hit` is None (a mesh) is hit
through a BVH walk over its pool, with the triangle test as the leaf.

The methods below run the kernels on whole arrays: `hits`, `normals_at`, `uv_at` and
`spans_of` on components (3, n), as the numpy engine calls them (a CSG, which has no
kernels, answers the same methods), and `intersect`, `normal`, `uv` and `spans` on
(n, 3) rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

POOL_WIDTH = 28                         # columns of a pool row (a mesh triangle is the widest)
REQUIRED = object()


class ShapeKernels(NamedTuple):
    hit: Callable | None
    normals: Callable
    uv: Callable
    spans: Callable | None = None


@dataclass(frozen=True)
class Param:
    """One YAML key of a shape: its kind ("number", "vector", "vectors", "boolean" or
    "obj", a mesh file), default (REQUIRED if none) and the checks the builder applies."""

    key: str
    kind: str
    default: object = REQUIRED
    positive: bool = False
    non_negative: bool = False
    count: int | None = None             # vectors: exactly this many
    min_count: int = 1                   # vectors: at least this many


class ParamError(ValueError):
    """A shape's parameters are inconsistent; `keys` names the YAML key(s) to blame (the
    builder reports the first one the file gives)."""

    def __init__(self, keys, message: str):
        super().__init__(message)
        self.keys = (keys,) if isinstance(keys, str) else tuple(keys)


class Shape:
    """Base of the shapes; see the module docstring."""

    __slots__ = ()                       # a shape may keep its state in slots (a sphere: its row)

    params: tuple = ()
    kernels: ShapeKernels
    SPANS = 1                            # intervals per ray that spans() returns
    FIRST_COLUMN: int | None = None      # the row's column holding its first pool row
    ROOT_COLUMN: int | None = None       # the row's column holding the root of its BVH (a mesh)
    row: np.ndarray = np.zeros(0)
    pool: np.ndarray = np.zeros((0, POOL_WIDTH))

    @classmethod
    def from_values(cls, **values) -> "Shape":
        """The shape from its parameters as the builder read them (keyword = YAML key)."""
        return cls(**values)

    @classmethod
    def examples(cls) -> list:
        """A few instances covering the shape's cases (the kernel tests check each one)."""
        return [cls()]

    @property
    def solid(self) -> bool:
        """Whether it encloses a volume (has spans), so it can be a CSG child."""
        return self.kernels.spans is not None

    def bounds(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Object-space box (lo, hi), or None when unbounded."""
        raise NotImplementedError

    # --- the kernels on arrays of rays and points as components (3, n) (the numpy engine) ---
    def hits(self, o, d, t_min, t_max):
        """(t, prim) (n,) for rays o + t d in object space, o and d (3, n)."""
        with np.errstate(all="ignore"):
            t, prim = self.kernels.hit(self.row, self.pool, *o, *d, t_min, t_max)
        n = o.shape[1]
        return np.broadcast_to(t, (n,)), np.broadcast_to(prim, (n,)).astype(np.int64)

    def normals_at(self, p, prim) -> tuple:
        """(n, g): the outward shading and geometric normals (3, n) at points p (3, n), any length."""
        with np.errstate(all="ignore"):
            c = self.kernels.normals(self.row, self.pool, prim, *p)
        n, g = np.broadcast_arrays(*c[:3], p[0]), np.broadcast_arrays(*c[3:], p[0])
        return np.array(n[:3]), np.array(g[:3])

    def uv_at(self, p, prim) -> tuple:
        """(u, v) (n,) at points p (3, n)."""
        with np.errstate(all="ignore"):
            u, v = self.kernels.uv(self.row, self.pool, prim, *p)
        return np.broadcast_to(u, p[0].shape), np.broadcast_to(v, p[0].shape)

    def texture_points(self, p, prim):
        """The points (3, n) where a checker is evaluated: p itself (a csg's: its leaves' own spaces)."""
        return p

    def spans_of(self, o, d):
        """(t_in, prim_in, t_out, prim_out), each (n, SPANS): the intervals inside the solid."""
        n = o.shape[1]
        if not self.solid:
            none, zero = np.full((n, 1), np.inf), np.zeros((n, 1), dtype=np.int64)
            return none, zero, none.copy(), zero.copy()
        with np.errstate(all="ignore"):
            parts = self.kernels.spans(self.row, self.pool, *o, *d)
        column = lambda k, dtype: np.stack([np.broadcast_to(parts[4 * j + k], (n,)) for j in range(self.SPANS)],
                                           axis=1).astype(dtype)
        return column(0, float), column(1, np.int64), column(2, float), column(3, np.int64)

    def material_of(self, prim, default: int):
        """Each hit's material row: the object's (a CSG's children may have their own)."""
        return np.full(len(prim), default, dtype=np.int64)

    # --- the same on (n, 3) arrays ---
    def intersect(self, o, d, t_min, t_max):
        """(t, prim) (n,) for rays o + t d in object space (n, 3)."""
        t, prim = self.hits(_columns(o), _columns(d), t_min, t_max)
        return t.copy(), prim.copy()

    def normal(self, p, prim) -> np.ndarray:
        """Outward shading normal (n, 3) at hit points p, any length."""
        return self.normals_at(_columns(p), np.asarray(prim))[0].T.copy()

    def geometric_normal(self, p, prim) -> np.ndarray:
        return self.normals_at(_columns(p), np.asarray(prim))[1].T.copy()

    def uv(self, p, prim) -> np.ndarray:
        """(n, 2) texture coordinates at hit points p."""
        return np.stack(self.uv_at(_columns(p), np.asarray(prim)), axis=1)

    def spans(self, o, d):
        return self.spans_of(_columns(o), _columns(d))


def _columns(a) -> np.ndarray:
    """(n, 3) rows as (3, n) components."""
    return np.ascontiguousarray(np.asarray(a, dtype=float).reshape(-1, 3).T)
