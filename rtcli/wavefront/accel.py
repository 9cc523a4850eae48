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
from rtcli.core.bvh import BVH
from rtcli.shapes.sphere import Sphere, nearest_root, sphere_roots
from rtcli.wavefront.intersect import (
    blocked_by,
    blocks,
    nearest_over,
    no_hits,
    object_hit,
)

MIN_OBJECTS = 8            # below this many bounded objects the plain loop is faster


class Accelerator:
    """The scene's unbounded objects, and a BVH over its bounded ones."""

    def __init__(self, scene):
        objects, boxes = scene.objects, scene.boxes
        self.unbounded = [k for k, b in enumerate(boxes) if b is None]
        self.members = np.array([k for k, b in enumerate(boxes) if b is not None], dtype=np.int64)
        self.bvh = BVH(np.array([boxes[k][0] for k in self.members]).reshape(-1, 3),
                       np.array([boxes[k][1] for k in self.members]).reshape(-1, 3), leaf_size=2)
        self.is_sphere = np.array([b is not None and isinstance(o.shape, Sphere) and o.world_from_object is None
                                   for o, b in zip(objects, boxes)], dtype=bool)     # by object index
        self.center = np.array([o.shape.center if s else np.zeros(3) for o, s in zip(objects, self.is_sphere)])
        self.radius = np.array([o.shape.radius if s else 1.0 for o, s in zip(objects, self.is_sphere)])
        self.material = np.array([o.material for o in objects], dtype=np.int64)
        self.shadow = scene.materials.shadow[self.material]
        self.all_spheres = bool(self.is_sphere[self.members].all())    # the compiled traversal can do it all
        k = self.members
        self.kernel_args = (self.center[k], (self.radius[k] ** 2)[:, None], np.ones((len(k), 1)))
        self.kernel_shadow = (self.center[k], (self.radius[k] ** 2)[:, None],
                              self.shadow[k].astype(float)[:, None])

    @staticmethod
    def wanted(scene) -> bool:
        """Whether the scene has enough bounded objects for the BVH to pay."""
        return sum(b is not None for b in scene.boxes) >= MIN_OBJECTS

    def _pair_test(self, scene, o, d, t_min, r, m, t_max):
        """(t, prim) of (ray r, member m) pairs in (t_min, t_max)."""
        obj = self.members[m]
        t, prim = np.full(len(r), np.inf), np.zeros(len(r), dtype=np.int64)
        sph = self.is_sphere[obj]
        if sph.any():
            k = obj[sph]
            roots = sphere_roots(o[r[sph]] - self.center[k], d[r[sph]], self.radius[k] ** 2)
            t[sph] = nearest_root(*roots, t_min, t_max[sph])
        rest = np.flatnonzero(~sph)
        for k in np.unique(obj[rest]):
            rows = rest[obj[rest] == k]
            t[rows], prim[rows] = object_hit(scene.objects[k], o[r[rows]], d[r[rows]], t_min, t_max[rows])
        return t, prim

    def _pair_blocks(self, scene, o, d, r, m):
        """Shadow feelers r (0 < t < 1) against members m: finite where blocked."""
        obj = self.members[m]
        blocked = np.zeros(len(r), dtype=bool)
        sph = self.shadow[obj] & self.is_sphere[obj]
        if sph.any():
            k = obj[sph]
            roots = sphere_roots(o[r[sph]] - self.center[k], d[r[sph]], self.radius[k] ** 2)
            blocked[sph] = np.isfinite(nearest_root(*roots, 0.0, 1.0))
        rest = np.flatnonzero(self.shadow[obj] & ~sph)
        for k in np.unique(obj[rest]):
            rows = rest[obj[rest] == k]
            blocked[rows] = blocks(scene.objects[k], o[r[rows]], d[r[rows]], 0.0, 1.0)
        return np.where(blocked, 0.5, np.inf)

    def first_hit(self, scene, rays, t_min):
        """find_first_hit through the BVH."""
        o, d = rays.origin, rays.direction
        hits = no_hits(len(rays))
        nearest_over(scene, self.unbounded, rays, t_min, hits)
        sub = np.zeros(len(rays), dtype=np.int64)      # which face of the winning object (0 for spheres)
        if kernels.available() and self.all_spheres:
            t, member = kernels.traverse(self.bvh, o, d, t_min, hits.t, 1, *self.kernel_args)
        else:
            pairs = lambda r, m, t_max: self._pair_test(scene, o, d, t_min, r, m, t_max)
            t, member = self.bvh.intersect(o, d, t_min, hits.t, pairs, sub)
        won = member >= 0
        hits.t[won], hits.obj[won], hits.prim[won] = t[won], self.members[member[won]], sub[won]
        return hits

    def occluded(self, scene, points, lights):
        """occluded() through the BVH: feelers stop at their first blocker."""
        d = lights - points
        blocked = np.zeros(len(points), dtype=bool)
        blocked_by(scene, self.unbounded, points, d, blocked)
        todo = np.flatnonzero(~blocked)
        p, dt = points[todo], d[todo]
        if kernels.available() and self.all_spheres:
            blocked[todo] = kernels.traverse(self.bvh, p, dt, 0.0, 1.0, 1, *self.kernel_shadow, any_hit=True)
        else:
            blocked[todo] = self.bvh.any_hit(p, dt, 0.0, 1.0, lambda r, m, t_max: self._pair_blocks(scene, p, dt, r, m))
        return blocked
