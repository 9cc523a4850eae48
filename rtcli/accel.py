"""Acceleration for scenes of many objects (notes 000 11.5: bounding volumes).

Unbounded objects (planes) are tested against every ray. Bounded objects go
into one BVH over their world-space boxes; the BVH hands back (ray, object)
pairs whose boxes the ray meets, and only those pairs are intersected. Spheres
without a transform, the common case in big scenes, are tested as one
vectorized batch per step; other objects are grouped per object.
"""

from __future__ import annotations

import numpy as np

from rtcli import kernels
from rtcli.bvh import BVH
from rtcli.shapes.sphere import Sphere, nearest_root, sphere_roots

MIN_OBJECTS = 8            # below this many bounded objects the plain loop is faster


class Accelerator:
    def __init__(self, scene):
        objects = scene.objects
        boxes = [o.bounds() for o in objects]
        self.unbounded = [k for k, b in enumerate(boxes) if b is None]
        self.members = np.array([k for k, b in enumerate(boxes) if b is not None], dtype=np.int64)
        self.bvh = BVH(np.array([boxes[k][0] for k in self.members]).reshape(-1, 3),
                       np.array([boxes[k][1] for k in self.members]).reshape(-1, 3), leaf_size=2)
        is_sphere = np.array([isinstance(objects[k].shape, Sphere) and objects[k].world_from_object is None
                              for k in self.members], dtype=bool)
        self.is_sphere = np.zeros(len(objects), dtype=bool)     # by object index, for surface()
        self.is_sphere[self.members[is_sphere]] = True
        self.center = np.array([o.shape.center if s else np.zeros(3) for o, s in zip(objects, self.is_sphere)])
        self.radius = np.array([o.shape.radius if s else 1.0 for o, s in zip(objects, self.is_sphere)])
        self.material = np.array([o.material for o in objects], dtype=np.int64)
        self.shadow = scene.materials.shadow[self.material]
        self.all_spheres = bool(is_sphere.all())       # then the compiled traversal can do it all
        k = self.members
        self.kernel_args = (self.center[k], (self.radius[k] ** 2)[:, None], np.ones((len(k), 1)))
        self.kernel_shadow = (self.center[k], (self.radius[k] ** 2)[:, None],
                              self.shadow[k].astype(float)[:, None])

    @staticmethod
    def wanted(scene) -> bool:
        return sum(o.bounds() is not None for o in scene.objects) >= MIN_OBJECTS

    def _pair_test(self, scene, o, d, t_min, r, m, t_max, only_shadow=False):
        """(t, prim) of (ray r, member m) pairs in (t_min, t_max)."""
        from rtcli.intersect import object_hit
        obj = self.members[m]
        t, prim = np.full(len(r), np.inf), np.zeros(len(r), dtype=np.int64)
        keep = self.shadow[obj] if only_shadow else np.ones(len(r), dtype=bool)
        sph = keep & self.is_sphere[obj]
        if sph.any():
            k = obj[sph]
            roots = sphere_roots(o[r[sph]] - self.center[k], d[r[sph]], self.radius[k] ** 2)
            t[sph] = nearest_root(*roots, t_min, t_max[sph])
        rest = np.flatnonzero(keep & ~sph)
        for k in np.unique(obj[rest]):
            rows = rest[obj[rest] == k]
            t[rows], prim[rows] = object_hit(scene.objects[k], o[r[rows]], d[r[rows]], t_min, t_max[rows])
        return t, prim

    def first_hit(self, scene, rays, t_min):
        from rtcli.intersect import Hits, object_hit
        o, d, n = rays.origin, rays.direction, len(rays)
        hits = Hits(np.full(n, np.inf), np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=np.int64))
        for k in self.unbounded:
            t, prim = object_hit(scene.objects[k], o, d, t_min, hits.t)
            closer = t < hits.t
            hits.t[closer], hits.obj[closer], hits.prim[closer] = t[closer], k, prim[closer]
        if kernels.available() and self.all_spheres:
            t, member = kernels.traverse(self.bvh, o, d, t_min, hits.t, 1, *self.kernel_args)
            won = member >= 0
            hits.t[won], hits.obj[won], hits.prim[won] = t[won], self.members[member[won]], 0
            return hits
        best, sub = hits.t.copy(), np.zeros(n, dtype=np.int64)

        def pairs(r, m, t_max):
            t, prim = self._pair_test(scene, o, d, t_min, r, m, t_max)
            hit = t < best[r]                  # mirrors the BVH's bookkeeping, to keep each winner's prim
            r_hit, t_hit = r[hit], t[hit]
            np.minimum.at(best, r_hit, t_hit)
            won = t_hit == best[r_hit]
            sub[r_hit[won]] = prim[hit][won]
            return t

        t, member = self.bvh.intersect(o, d, t_min, hits.t, pairs)
        won = member >= 0
        hits.t[won], hits.obj[won], hits.prim[won] = t[won], self.members[member[won]], sub[won]
        return hits

    def occluded(self, scene, points, lights):
        from rtcli.intersect import object_hit
        d = lights - points
        blocked = np.zeros(len(points), dtype=bool)
        for k in self.unbounded:
            if self.shadow[k]:
                todo = np.flatnonzero(~blocked)
                t, _ = object_hit(scene.objects[k], points[todo], d[todo], 0.0, 1.0)
                blocked[todo] = np.isfinite(t)
        todo = np.flatnonzero(~blocked)
        if kernels.available() and self.all_spheres:
            blocked[todo] = kernels.traverse(self.bvh, points[todo], d[todo], 0.0, 1.0, 1,
                                             *self.kernel_shadow, any_hit=True)
            return blocked
        pairs = lambda r, m, t_max: self._pair_test(scene, points[todo], d[todo], 0.0, r, m, t_max, True)[0]
        blocked[todo] = self.bvh.any_hit(points[todo], d[todo], 0.0, 1.0, pairs)
        return blocked

