"""Acceleration for scenes of many objects (notes 000 11.5: bounding volumes).

Unbounded objects (planes) are tested against every ray. Bounded objects go
into one BVH over their world-space boxes; the BVH hands back (ray, object)
pairs whose boxes the ray meets, and only those pairs are intersected. Spheres
without a transform, the common case in big scenes, are tested as one
vectorized batch per step (the sphere kernels take one row of parameters per
ray); other objects are grouped per object. When every bounded object is such a
sphere and the scene was given compiled walks (Scene.walks: rendering/engine.py gives them
when numba is installed), the per-ray walk of rtcli/core/bvh.py does the whole BVH part.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.bvh import ANY_CASTER, NEAREST, NEAREST_CASTER
from rtcli.core.objects import object_materials, singles, sphere_blocks
from rtcli.core.scene import object_tree
from rtcli.core.vec import unit
from rtcli.shapes.sphere import Sphere
from rtcli.kernels.variants import INF, select
from rtcli.wavefront.intersect import (
    blocked_by,
    blocks,
    fill_texture,
    nearest_over,
    no_hits,
    object_hit,
)


class Accelerator:
    """The scene's unbounded objects, and a BVH over its bounded ones."""

    def __init__(self, scene, levels=None):
        objects, bounded = scene.objects, scene.boxes.bounded
        self.unbounded = np.flatnonzero(~bounded)
        self.members, self.bvh = object_tree(scene, levels)
        n = len(objects)
        self.is_sphere, self.spheres = np.zeros(n, dtype=bool), np.zeros((5, n))     # by object index
        for k, o in singles(objects):
            self.is_sphere[k] = type(o.shape) is Sphere and o.transform is None and bounded[k]
            if self.is_sphere[k]:
                self.spheres[:, k] = o.shape.row
        for start, block in sphere_blocks(objects):              # spheres kept as arrays (core/objects.py)
            end = start + len(block)
            self.is_sphere[start:end], self.spheres[:, start:end] = True, block.rows.T
        self.material = object_materials(objects)
        self.shadow = scene.materials.shadow[self.material]
        self.all_spheres = bool(self.is_sphere[self.members].all())    # the compiled walk can do it all

    def batched(self, obj: np.ndarray) -> np.ndarray:
        """Which hits (object indices, -1 none) are on untransformed spheres."""
        return self.is_sphere[obj]

    # --- first hits and feelers ---
    def _sphere_t(self, o, d, r, k, t_min, t_max):
        """t of rays r against spheres k (object indices), pair by pair."""
        with np.errstate(all="ignore"):
            t, _ = Sphere.kernels.hit(self.spheres[:, k], None, *o[:, r], *d[:, r], t_min, t_max)
        return t

    def _pair_test(self, scene, o, d, t_min, r, m, t_max, casters: bool = False):
        """(t, prim) of (ray r, member m) pairs in (t_min, t_max) (with `casters`: members that
        cast shadows only)."""
        obj = self.members[m]
        t, prim = np.full(len(r), np.inf), np.zeros(len(r), dtype=np.int64)
        low = np.asarray(t_min, dtype=float)
        low = low if low.ndim == 0 else low[r]
        live = self.shadow[obj] if casters else np.ones(len(r), dtype=bool)
        sph = self.is_sphere[obj] & live
        if sph.any():
            t[sph] = self._sphere_t(o, d, r[sph], obj[sph], low if low.ndim == 0 else low[sph], t_max[sph])
        rest = np.flatnonzero(~self.is_sphere[obj] & live)
        for k in np.unique(obj[rest]):
            rows = rest[obj[rest] == k]
            t[rows], prim[rows] = object_hit(scene.objects[k], o[:, r[rows]], d[:, r[rows]],
                                             low if low.ndim == 0 else low[rows], t_max[rows], scene.walks)
        return t, prim

    def _pair_blocks(self, scene, o, d, r, m):
        """Shadow feelers r (0 < t < 1) against members m: finite where blocked."""
        obj = self.members[m]
        blocked = np.zeros(len(r), dtype=bool)
        sph = self.shadow[obj] & self.is_sphere[obj]
        if sph.any():
            blocked[sph] = np.isfinite(self._sphere_t(o, d, r[sph], obj[sph], 0.0, 1.0))
        rest = np.flatnonzero(self.shadow[obj] & ~sph)
        for k in np.unique(obj[rest]):
            rows = rest[obj[rest] == k]
            blocked[rows] = blocks(scene.objects[k], o[:, r[rows]], d[:, r[rows]], 0.0, 1.0, scene.walks)
        return select(blocked, 0.5, INF)

    def first_hit(self, scene, rays, t_min, t_max=np.inf, casters: bool = False):
        """find_first_hit through the BVH (with `casters`, among the objects that cast shadows)."""
        o, d = rays.o, rays.d
        hits = no_hits(len(rays), t_max)
        nearest_over(scene, self.unbounded, rays, t_min, hits, casters)
        if scene.walks is not None and self.all_spheres:
            t, obj, sub = scene.walks.objects(self, scene, o, d, t_min, hits.t, NEAREST_CASTER if casters else NEAREST)
            won = obj >= 0
            hits.t[won], hits.obj[won], hits.prim[won] = t[won], obj[won], sub[won]
            return hits
        sub = np.zeros(len(rays), dtype=np.int64)      # which face of the winning object (0 for spheres)
        pairs = lambda r, m, t_max: self._pair_test(scene, o, d, t_min, r, m, t_max, casters)
        t, member = self.bvh.intersect(o, d, t_min, hits.t, pairs, sub)
        won = member >= 0
        hits.t[won], hits.obj[won], hits.prim[won] = t[won], self.members[member[won]], sub[won]
        return hits

    def occluded(self, scene, points, lights):
        """occluded() through the BVH: feelers stop at their first blocker."""
        d = lights - points
        blocked = np.zeros(points.shape[1], dtype=bool)
        blocked_by(scene, self.unbounded, points, d, blocked)
        todo = np.flatnonzero(~blocked)
        p, dt = points[:, todo], d[:, todo]
        if scene.walks is not None and self.all_spheres:
            blocked[todo] = scene.walks.objects(self, scene, p, dt, 0.0, 1.0, ANY_CASTER)[1] >= 0
        else:
            blocked[todo] = self.bvh.any_hit(p, dt, 0.0, 1.0, lambda r, m, t_max: self._pair_blocks(scene, p, dt, r, m))
        return blocked

    # --- surfaces ---
    def sphere_surface(self, scene, p, obj, rows, normal, geometric, material, texture) -> None:
        """Fill the surface arrays at `rows` for hits p (3, n) on untransformed spheres obj."""
        rows_of = self.spheres[:, obj]
        with np.errstate(all="ignore"):
            n = unit(*Sphere.kernels.normals(rows_of, None, 0, *p)[:3])
        normal[:, rows] = geometric[:, rows] = n
        material[rows] = self.material[obj]
        fill_texture(scene, p, lambda sel: Sphere.kernels.uv(rows_of[:, sel], None, 0, *p[:, sel]), material[rows],
                     texture, rows)
