"""Ray-scene queries: the first hit (findFirstHit of notes 000 11.7), the surface at
each hit, and shadow feelers.

`t` first, surface second: `find_first_hit` keeps only the nearest t and which
object and primitive gave it; `surface` then computes points, normals, (u, v)
and texture colors for the rays that hit something.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.bvh import columns, slab
from rtcli.core.scene import Scene
from rtcli.core.vec import dot, normalize
from rtcli.shapes.sphere import sphere_uv
from rtcli.wavefront.rays import Rays


@dataclass(frozen=True)
class Hits:
    t: np.ndarray           # (n,) nearest t > t_min, inf on a miss
    obj: np.ndarray         # (n,) index into scene.objects, -1 on a miss
    prim: np.ndarray        # (n,) which surface/triangle of that object

    def __getitem__(self, which) -> "Hits":
        return Hits(self.t[which], self.obj[which], self.prim[which])


@dataclass(frozen=True)
class Surface:
    p: np.ndarray           # (n, 3) hit points, world space
    n: np.ndarray           # (n, 3) unit shading normal, turned to face the incoming ray
    ng: np.ndarray          # (n, 3) unit geometric normal, same side as n (for offsets)
    entering: np.ndarray    # (n,) the ray arrives on the outside (d . outward normal < 0)
    material: np.ndarray    # (n,) row of the MaterialTable
    texture: np.ndarray     # (n, 3) texture color T (1 without a texture)


def object_hit(obj, o, d, t_min, t_max):
    """(t, prim) of one scene object for rays o + t d in world space."""
    o_obj, d_obj = obj.to_object(o, d)
    t, prim = obj.shape.intersect(o_obj, d_obj, t_min, t_max)
    return t, (np.zeros(len(o), dtype=np.int64) if prim is None else prim)


def blocks(obj, o, d, t_min, t_max) -> np.ndarray:
    """(n,) bool: the rays o + t d hit object obj for t_min < t < t_max (any hit will do)."""
    o_obj, d_obj = obj.to_object(o, d)
    if hasattr(obj.shape, "any_hit"):                  # meshes stop at their first blocking triangle
        return obj.shape.any_hit(o_obj, d_obj, t_min, t_max)
    return np.isfinite(obj.shape.intersect(o_obj, d_obj, t_min, t_max)[0])


def _candidates(scene: Scene, k: int, o_cols, inv_cols, rows, t_max):
    """The rows whose ray meets object k's world box before t_max (all rows if unbounded)."""
    box = scene.boxes[k]
    if box is None or len(rows) == 0:
        return rows
    return rows[slab(o_cols[:, rows], inv_cols[:, rows], box[0], box[1], 0.0, t_max)]


def nearest_over(scene: Scene, indices, rays: Rays, t_min: float, best: Hits) -> None:
    """Lower `best` to the nearest hit among the objects `indices`, each tested only on
    the rays that meet its bounding box before the best hit so far."""
    o_cols, inv_cols = columns(rays.origin, rays.direction)
    every = np.arange(len(rays))
    for k in indices:
        rows = _candidates(scene, k, o_cols, inv_cols, every, best.t)
        if len(rows):
            t, prim = object_hit(scene.objects[k], rays.origin[rows], rays.direction[rows], t_min, best.t[rows])
            closer = t < best.t[rows]
            won = rows[closer]
            best.t[won], best.obj[won], best.prim[won] = t[closer], k, prim[closer]


def blocked_by(scene: Scene, indices, points: np.ndarray, d: np.ndarray, blocked: np.ndarray) -> None:
    """Mark the feelers points + t d (0 < t < 1) that an object of `indices` casting shadows
    blocks; a feeler stops at its first blocker: later objects test only the open ones."""
    o_cols, inv_cols = columns(points, d)
    for k in indices:
        if scene.materials.shadow[scene.objects[k].material]:
            todo = _candidates(scene, k, o_cols, inv_cols, np.flatnonzero(~blocked), 1.0)
            if len(todo):
                blocked[todo] = blocks(scene.objects[k], points[todo], d[todo], 0.0, 1.0)


def no_hits(n: int) -> Hits:
    return Hits(np.full(n, np.inf), np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=np.int64))


def find_first_hit(scene: Scene, rays: Rays, t_min: float = 0.0) -> Hits:
    """Nearest hit over all objects: through the BVH when the scene has one, else
    object by object, each tested only on the rays that meet its bounding box."""
    if scene.accel is not None:
        return scene.accel.first_hit(scene, rays, t_min)
    best = no_hits(len(rays))
    nearest_over(scene, range(len(scene.objects)), rays, t_min, best)
    return best


def occluded(scene: Scene, points: np.ndarray, lights: np.ndarray) -> np.ndarray:
    """Shadow feelers p + t (l - p): True where an object that casts shadows is hit for 0 < t < 1."""
    if scene.accel is not None:
        return scene.accel.occluded(scene, points, lights)
    blocked = np.zeros(len(points), dtype=bool)
    blocked_by(scene, range(len(scene.objects)), points, lights - points, blocked)
    return blocked


def surface(scene: Scene, rays: Rays, hits: Hits) -> Surface:
    """The surface record of rays that hit (notes 000 11.6): normals by A^-T n, (u, v), T."""
    n = len(rays)
    p = rays.at(hits.t)
    normal, geometric = np.empty((n, 3)), np.empty((n, 3))
    material, texture = np.empty(n, dtype=np.int64), np.ones((n, 3))
    batched = scene.accel.is_sphere[hits.obj] if scene.accel is not None else np.zeros(n, dtype=bool)
    if batched.any():                                    # untransformed spheres, all at once
        rows = np.flatnonzero(batched)
        k = hits.obj[rows]
        q = (p[rows] - scene.accel.center[k]) / scene.accel.radius[k, None]
        normal[rows] = geometric[rows] = normalize(q)   # as _object_surface: unit to the last bit
        material[rows] = scene.accel.material[k]
        _texture(scene, p[rows], lambda sel: sphere_uv(q[sel]), material[rows], texture, rows)
    for k in np.flatnonzero(np.bincount(hits.obj[~batched], minlength=len(scene.objects))):
        rows = np.flatnonzero((hits.obj == k) & ~batched)
        _object_surface(scene, scene.objects[k], rays, hits, rows, normal, geometric, material, texture)
    entering = dot(rays.direction, geometric) < 0
    facing = np.where(entering, 1.0, -1.0)[:, None]
    n_face = normal * facing
    n_face = np.where((dot(n_face, rays.direction) > 0)[:, None], geometric * facing, n_face)
    return Surface(p, n_face, geometric * facing, entering, material, texture)


def _object_surface(scene, obj, rays, hits, rows, normal, geometric, material, texture) -> None:
    """Fill the surface arrays at `rows`, all hits on one object."""
    o_obj, d_obj = obj.to_object(rays.origin[rows], rays.direction[rows])
    p_obj = o_obj + hits.t[rows, None] * d_obj
    prim = hits.prim[rows]
    ns = obj.shape.normal(p_obj, prim)
    ng = obj.shape.geometric_normal(p_obj, prim) if hasattr(obj.shape, "geometric_normal") else ns
    mat = obj.shape.material_of(prim, obj.material) if hasattr(obj.shape, "material_of") \
        else np.full(len(rows), obj.material)
    same = ng is ns
    if obj.world_from_object is not None:
        ns = obj.world_from_object.normal(ns)
        ng = ns if same else obj.world_from_object.normal(ng)
    normal[rows] = normalize(ns)
    geometric[rows], material[rows] = normal[rows] if same else normalize(ng), mat
    _texture(scene, p_obj, lambda sel: obj.shape.uv(p_obj[sel], prim[sel]), mat, texture, rows)


def _texture(scene, p_obj, uv_of, mat, texture, rows) -> None:
    """Fill texture[rows] for the textured materials among `mat`; uv_of(selection) gives (u, v)."""
    table = scene.materials
    for m in table.textured:
        sel = mat == m
        if sel.any():
            texture[rows[sel]] = table.materials[m].texture.color(p_obj[sel], uv_of(sel))
