"""Triangle mesh (from a Wavefront OBJ file), hit through its own BVH.

YAML: `mesh: {file: model.obj, smooth: false}`; `file` is relative to the scene
file's folder (the scene-file builder reads it; a Mesh is built from the arrays).
Triangles with zero area are skipped; `prim` is the index of a kept triangle, in
file order.

Normals: flat (smooth: false) = the face normal, outward by the vertex order
(right-hand rule, as `triangle`). Smooth = the file's vn interpolated with the
barycentric coordinates, or where a face has no vn, area-weighted vertex
normals (the sum of the adjacent faces' (b - a) x (c - a)).
(u, v): the file's vt interpolated where the face has them, else the
barycentric coordinates (alpha, beta) of notes 000 11.3.1, as `triangle`.

The faces are triangle rows of the pool (triangle.py), with the triangle's normal and
(u, v) kernels. A mesh has no hit kernel of its own: it is hit through a BVH over its
faces, walked with triangle_t as the leaf test (numpy's level-by-level walk here, the
compiled per-ray walk in rtcli/core/bvh.py), built on first use. A mesh has no spans: it need not be
closed, so it cannot take part in CSG.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.bvh import BVH
from rtcli.core.vec import cross3, length3
from rtcli.shapes.base import Param, ParamError, Shape, ShapeKernels
from rtcli.shapes.triangle import (
    FIRST,
    ROOT,
    degenerate,
    normals,
    triangle_rows,
    triangle_t,
    uv,
)
from rtcli.kernels.variants import INF, select


class Mesh(Shape):
    """Triangles a, b, c = vertices[faces]; optional per-corner vt / vn (index -1: none)."""

    params = (Param("file", "obj"), Param("smooth", "boolean", False))
    kernels = ShapeKernels(None, normals, uv)
    FIRST_COLUMN = FIRST
    ROOT_COLUMN = ROOT

    def __init__(self, vertices, faces, smooth=False, uv=None, uv_faces=None, normals=None, normal_faces=None):
        v, f = np.asarray(vertices, dtype=float).reshape(-1, 3), np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        if len(f) == 0:
            raise ParamError("file", "the mesh has no faces")
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        keep = ~degenerate(a, b, c)                                        # as triangle: not collinear
        if not keep.any():
            raise ParamError("file", "all triangles of the mesh have zero area")
        a, b, c = a[keep], b[keep], c[keep]
        uvs = _corners(uv, uv_faces, keep)                                 # (F, 3, 2) or None
        corner_normals = _smooth_normals(v, f[keep], cross3(b - a, c - a), normals, normal_faces, keep) \
            if smooth else None
        self.pool = triangle_rows(a, b, c, corner_normals, uvs)
        self._boxes = np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)
        self._box, self._bvh = (self._boxes[0].min(axis=0), self._boxes[1].max(axis=0)), None
        self.row = np.array([0.0, float(smooth), float(uvs is not None), 0.0])
        self.smooth = bool(smooth)

    @classmethod
    def from_values(cls, file, smooth=False) -> "Mesh":
        """From an OBJ file's arrays (rtcli.scenefile.obj.ObjData)."""
        return cls(file.vertices, file.faces, smooth, file.uv, file.uv_faces, file.normals, file.normal_faces)

    def __len__(self) -> int:
        return len(self.pool)

    @property
    def bvh(self) -> BVH:
        """The BVH over the faces' boxes, built when first asked for (checking a scene needs only
        its bounds), by numpy unless a render built it first (tree)."""
        return self.tree()

    def tree(self, levels=None) -> BVH:
        """The BVH over the faces' boxes, built now if it was not, by `levels` when given (the
        compiled build the engine choice hands a render: core/bvh_build.py)."""
        if self._bvh is None:
            self._bvh, self._boxes = BVH(*self._boxes, levels=levels), None
        return self._bvh

    def bounds(self):
        return self._box[0].copy(), self._box[1].copy()

    # --- the numpy walk (the compiled one: rtcli.core.bvh.walk) ---
    def hits(self, o, d, t_min, t_max):
        """Nearest triangle hit in (t_min, t_max) of rays o, d (3, n): (t, prim), inf and -1 for a miss."""
        return self.bvh.intersect(o, d, t_min, t_max, self.pair_test(o, d, t_min))

    def any_hit(self, o, d, t_min, t_max) -> np.ndarray:
        """(n,) bool: some triangle is hit in (t_min, t_max) (shadow feelers); o, d (3, n)."""
        return self.bvh.any_hit(o, d, t_min, t_max, self.pair_test(o, d, t_min))

    def pair_test(self, o, d, t_min):
        """The BVH's callback for rays o, d (3, n): rays r against triangles p, pair by pair."""
        t_min = np.asarray(t_min, dtype=float)

        def hit_pairs(r, p, t_max):
            with np.errstate(all="ignore"):
                t = triangle_t(self.pool, p, *o[:, r], *d[:, r])
            lo = t_min if t_min.ndim == 0 else t_min[r]
            return select((t > lo) & (t < t_max), t, INF)
        return hit_pairs

    @classmethod
    def examples(cls) -> list:
        """A closed octahedron, flat and smooth, and a random soup of triangles with (u, v)s."""
        v = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
        f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
        rng = np.random.default_rng(3)
        soup = rng.normal(size=(90, 3))
        return [cls(v, f), cls(v * [1, 0.7, 1.3], f, smooth=True),
                cls(soup, np.arange(90).reshape(30, 3), uv=rng.uniform(0, 1, (90, 2)),
                    uv_faces=np.arange(90).reshape(30, 3))]


def _corners(values, index, keep):
    """(F, 3, k) per-corner values of the kept faces, NaN for faces missing any index; None if none."""
    if values is None or len(values) == 0 or index is None or not (index[keep] >= 0).all(axis=1).any():
        return None
    index = index[keep]
    out = np.asarray(values, dtype=float)[np.maximum(index, 0)]
    out[~(index >= 0).all(axis=1)] = np.nan
    return out


def _smooth_normals(v, faces, face, normals, normal_faces, keep):
    """(F, 3, 3) unit corner normals: the file's vn, else area-weighted vertex normals."""
    summed = np.stack([np.bincount(faces.ravel(), weights=np.repeat(face[:, j], 3), minlength=len(v))
                       for j in range(3)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.nan_to_num(summed / length3(summed)[:, None])[faces]
        given = _corners(normals, normal_faces, keep)
        if given is not None:
            given = given / length3(given)[..., None]
            out = np.where(np.isnan(given), out, given)
    return np.nan_to_num(out)
