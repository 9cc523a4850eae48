"""Triangle mesh read from a Wavefront OBJ file, intersected through its own BVH.

YAML: `mesh: {file: model.obj, smooth: false}`; `file` is relative to the scene
file's folder. Triangles with zero area are skipped; `prim` is the index of a
kept triangle, in file order.

Normals: flat (smooth: false) = the face normal, outward by the vertex order
(right-hand rule, as `triangle`). Smooth = the file's vn interpolated with the
barycentric coordinates, or where a face has no vn, area-weighted vertex
normals (the sum of the adjacent faces' (b - a) x (c - a)).
(u, v): the file's vt interpolated where the face has them, else the
barycentric coordinates (alpha, beta) of notes 000 11.3.1, as `triangle`.

A mesh has no `spans`: it need not be closed, so it cannot take part in CSG.
"""

from __future__ import annotations

import os

import numpy as np

from rtcli import kernels
from rtcli.core.bvh import BVH
from rtcli.core.vec import cross, length
from rtcli.scenefile.obj import read_obj
from rtcli.shapes.planar import barycentric, degenerate, triangle_solve


class Mesh:
    """Triangles a, b, c = vertices[faces]; optional per-corner vt / vn (index -1: none)."""

    def __init__(self, vertices, faces, smooth=False, uv=None, uv_faces=None, normals=None, normal_faces=None):
        v, f = np.asarray(vertices, dtype=float).reshape(-1, 3), np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        if len(f) == 0:
            raise ValueError("the mesh has no faces")
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        keep = ~degenerate(a, b, c)                                        # as triangle: not collinear
        if not keep.any():
            raise ValueError("all triangles of the mesh have zero area")
        self.a, self.e1, self.e2 = a[keep], (b - a)[keep], (c - a)[keep]
        self.face = cross(self.e1, self.e2)                                # outward, |face| = 2 area
        self.uv_corners = _corners(uv, uv_faces, keep)                     # (F, 3, 2) or None
        self.normal_corners = (_smooth_normals(v, f[keep], self.face, normals, normal_faces, keep)
                               if smooth else None)                       # (F, 3, 3) or None
        self.bvh = BVH(np.minimum(np.minimum(a, b), c)[keep], np.maximum(np.maximum(a, b), c)[keep])

    @classmethod
    def from_params(cls, p):
        name, smooth = p.string("file"), p.boolean("smooth", False)
        path = os.path.normpath(os.path.join(p.folder, name))
        try:
            data = read_obj(path)
        except FileNotFoundError:
            raise p.error("file", f"file not found: {path}") from None
        except OSError as e:
            raise p.error("file", f"cannot read {path}: {e.strerror}") from None
        try:
            return cls(data.vertices, data.faces, smooth, data.uv, data.uv_faces, data.normals, data.normal_faces)
        except ValueError as e:
            raise p.error("file", f"{e}: {path}") from None

    # --- intersection ---
    def intersect(self, o, d, t_min, t_max):
        """Nearest triangle hit in (t_min, t_max): (t, prim), inf and -1 for a miss."""
        if kernels.available():
            return kernels.traverse(self.bvh, o, d, t_min, t_max, 0, self.a, self.e1, self.e2)
        return self.bvh.intersect(o, d, t_min, t_max, self._pair_test(o, d, t_min))

    def any_hit(self, o, d, t_min, t_max):
        """(n,) bool: some triangle is hit in (t_min, t_max) (shadow feelers)."""
        if kernels.available():
            return kernels.traverse(self.bvh, o, d, t_min, t_max, 0, self.a, self.e1, self.e2, any_hit=True)
        return self.bvh.any_hit(o, d, t_min, t_max, self._pair_test(o, d, t_min))

    def _pair_test(self, o, d, t_min):
        """The BVH's callback: rays r against triangles p, pair by pair."""
        o, d, t_min = np.asarray(o, dtype=float), np.asarray(d, dtype=float), np.asarray(t_min, dtype=float)

        def hit_pairs(r, p, t_max):
            t, alpha, beta = triangle_solve(o[r], d[r], self.a[p], self.e1[p], self.e2[p])
            lo = t_min if t_min.ndim == 0 else t_min[r]
            inside = (alpha >= 0) & (beta >= 0) & (alpha + beta <= 1)
            return np.where(inside & (t > lo) & (t < t_max), t, np.inf)
        return hit_pairs

    # --- surface ---
    def barycentric(self, p, prim):
        """(alpha, beta) of points p in the planes of triangles prim (weights of b and c)."""
        return barycentric(p - self.a[prim], self.e1[prim], self.e2[prim])

    def geometric_normal(self, p, prim):
        return self.face[prim]

    def normal(self, p, prim):
        if self.normal_corners is None:
            return self.face[prim]
        n = _interpolate(self.normal_corners[prim], *self.barycentric(p, prim))
        return np.where(length(n)[:, None] > 0, n, self.face[prim])

    def uv(self, p, prim):
        alpha, beta = self.barycentric(p, prim)
        bary = np.stack([alpha, beta], axis=1)
        if self.uv_corners is None:
            return bary
        uv = _interpolate(self.uv_corners[prim], alpha, beta)
        return np.where(np.isnan(uv), bary, uv)                       # faces without vt

    def bounds(self):
        return self.bvh.bounds()


def _interpolate(corners, alpha, beta):
    """(1 - alpha - beta) x corner a + alpha x corner b + beta x corner c; corners (n, 3, k)."""
    return ((1 - alpha - beta)[:, None] * corners[:, 0] + alpha[:, None] * corners[:, 1]
            + beta[:, None] * corners[:, 2])


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
        out = np.nan_to_num(summed / length(summed)[:, None])[faces]
        given = _corners(normals, normal_faces, keep)
        if given is not None:
            given = given / length(given)[..., None]
            out = np.where(np.isnan(given), out, given)
    return np.nan_to_num(out)
