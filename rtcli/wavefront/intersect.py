"""Ray-scene queries on arrays of rays: the first hit (findFirstHit of notes 000 11.7), the
surface at each hit, and shadow feelers.

`t` first, surface second: `find_first_hit` keeps only the nearest t and which
object and primitive gave it; `surface` then computes points, normals, (u, v)
and texture colors for the rays that hit something, with the shapes' and the core's
kernels. Vectors are components (3, n).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.bvh import slab
from rtcli.core.dielectric import FEELER_CROSSINGS
from rtcli.core.scene import Scene
from rtcli.core.shading import facing
from rtcli.core.textures import IMAGE, KIND, texture_color
from rtcli.core.transform import WORLD, linear, normal_to_world, ray_to_object
from rtcli.core.vec import unit
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.triangle import SMOOTH, Triangle, terminator
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
    p: np.ndarray           # (3, n) hit points, world space
    n: np.ndarray           # (3, n) unit shading normal, turned to face the incoming ray
    ng: np.ndarray          # (3, n) unit geometric normal, same side as n (for offsets)
    entering: np.ndarray    # (n,) the ray arrives on the outside (d . outward normal < 0)
    obj: np.ndarray         # (n,) index into scene.objects (which solid a refracted ray enters or leaves)
    material: np.ndarray    # (n,) row of the MaterialTable
    texture: np.ndarray     # (3, n) texture color T (1 without a texture)
    lift: np.ndarray | None = None  # (3, n) where feelers leave from, less p (render: {shadow_terminator: offset})


def to_object(obj, o, d):
    """Rays o, d (3, n) in the object's space (notes 000 11.3.4)."""
    if obj.transform is None:
        return o, d
    c = ray_to_object(obj.transform, 0, *o, *d)
    return np.array(c[:3]), np.array(c[3:])


def walked_mesh(shape, walks) -> bool:
    """Whether the shape is hit through a BVH over pool triangles (a mesh) and `walks` (Scene.walks,
    the compiled walks, when the engine choice gave them) walks it."""
    return walks is not None and shape.kernels is not None and shape.kernels.hit is None


def object_hit(obj, o, d, t_min, t_max, walks=None):
    """(t, prim) of one scene object for rays o + t d in world space (`walks`: Scene.walks)."""
    o_obj, d_obj = to_object(obj, o, d)
    if walked_mesh(obj.shape, walks):
        return walks.mesh(obj.shape, o_obj, d_obj, t_min, t_max, False)
    return obj.shape.hits(o_obj, d_obj, t_min, t_max)


def blocks(obj, o, d, t_min, t_max, walks=None) -> np.ndarray:
    """(n,) bool: the rays o + t d hit object obj for t_min < t < t_max (any hit will do)."""
    o_obj, d_obj = to_object(obj, o, d)
    if walked_mesh(obj.shape, walks):
        return walks.mesh(obj.shape, o_obj, d_obj, t_min, t_max, True)
    if hasattr(obj.shape, "any_hit"):                  # meshes stop at their first blocking triangle
        return obj.shape.any_hit(o_obj, d_obj, t_min, t_max)
    return np.isfinite(obj.shape.hits(o_obj, d_obj, t_min, t_max)[0])


def _candidates(scene: Scene, k: int, o, inv, rows, t_max):
    """The rows whose ray meets object k's world box before t_max (all rows if unbounded)."""
    box = scene.boxes[k]
    if box is None or len(rows) == 0:
        return rows
    with np.errstate(invalid="ignore"):
        t_in, t_out = slab(*box[0], *box[1], *o[:, rows], *inv[:, rows], 0.0, t_max)
    return rows[t_in <= t_out]


def reciprocal(d):
    with np.errstate(divide="ignore"):
        return 1.0 / d


def casts(scene: Scene, k: int) -> bool:
    """Whether object k stops or filters shadow feelers."""
    return bool(scene.materials.shadow[scene.objects[k].material])


def nearest_over(scene: Scene, indices, rays: Rays, t_min, best: Hits, casters: bool = False) -> None:
    """Lower `best` to the nearest hit among the objects `indices` (with `casters`, those that
    cast shadows), each tested only on the rays that meet its bounding box before the best hit so
    far. t_min: a number, or one per ray."""
    inv, every = reciprocal(rays.d), np.arange(len(rays))
    t_min = np.asarray(t_min, dtype=float)
    for k in indices:
        if casters and not casts(scene, k):
            continue
        rows = _candidates(scene, k, rays.o, inv, every, best.t)
        if len(rows):
            low = t_min if t_min.ndim == 0 else t_min[rows]
            t, prim = object_hit(scene.objects[k], rays.o[:, rows], rays.d[:, rows], low, best.t[rows], scene.walks)
            closer = t < best.t[rows]
            won = rows[closer]
            best.t[won], best.obj[won], best.prim[won] = t[closer], k, prim[closer]


def blocked_by(scene: Scene, indices, points: np.ndarray, d: np.ndarray, blocked: np.ndarray) -> None:
    """Mark the feelers points + t d (0 < t < 1) that an object of `indices` casting shadows
    blocks; a feeler stops at its first blocker: later objects test only the open ones."""
    inv = reciprocal(d)
    for k in indices:
        if casts(scene, k):
            todo = _candidates(scene, k, points, inv, np.flatnonzero(~blocked), 1.0)
            if len(todo):
                blocked[todo] = blocks(scene.objects[k], points[:, todo], d[:, todo], 0.0, 1.0, scene.walks)


def no_hits(n: int, t_max=np.inf) -> Hits:
    """No hit yet: t = t_max (a number or one per ray), object -1."""
    t = np.broadcast_to(np.asarray(t_max, dtype=float), (n,)).copy()
    return Hits(t, np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=np.int64))


def find_first_hit(scene: Scene, rays: Rays, t_min=0.0, t_max=np.inf, casters: bool = False) -> Hits:
    """Nearest hit in (t_min, t_max) over all objects (with `casters`, over those that cast
    shadows): through the BVH when the scene has one, else object by object, each tested only
    on the rays that meet its bounding box. Misses have t = inf."""
    if scene.accel is not None:
        best = scene.accel.first_hit(scene, rays, t_min, t_max, casters)
    else:
        best = no_hits(len(rays), t_max)
        nearest_over(scene, range(len(scene.objects)), rays, t_min, best, casters)
    best.t[best.obj < 0] = np.inf
    return best


def occluded(scene: Scene, points: np.ndarray, lights: np.ndarray) -> np.ndarray:
    """Shadow feelers p + t (l - p), (3, n) each: True where an object that casts shadows is hit
    for 0 < t < 1."""
    if scene.accel is not None:
        return scene.accel.occluded(scene, points, lights)
    blocked = np.zeros(points.shape[1], dtype=bool)
    blocked_by(scene, range(len(scene.objects)), points, lights - points, blocked)
    return blocked


def transmittance(scene: Scene, points: np.ndarray, lights: np.ndarray) -> np.ndarray:
    """(3, n): how much of each light reaches each point along the feeler p + t (l - p), 0 < t < 1.
    An object that casts a full shadow stops it (0); one with `shadow: filter` lets it through,
    times its material's kt at each surface crossed (docs/scene-format.md, Shading), up to
    FEELER_CROSSINGS crossings. Without such materials this is occluded(), as 0 or 1."""
    n = points.shape[1]
    if not scene.materials.filters.any():
        return np.repeat((~occluded(scene, points, lights)).astype(float)[None], 3, axis=0)
    T, d, t0, todo = np.ones((3, n)), lights - points, np.zeros(n), np.arange(n)
    for _ in range(FEELER_CROSSINGS):
        hits = find_first_hit(scene, Rays(points[:, todo], d[:, todo]), t0[todo], 1.0, casters=True)
        got = np.isfinite(hits.t)
        todo, hits = todo[got], hits[got]
        if not len(todo):
            return T
        material = hit_materials(scene, hits)
        clear = scene.materials.filters[material]
        T[:, todo[~clear]] = 0.0
        T[:, todo[clear]] *= scene.materials.kt[material[clear]].T
        t0[todo[clear]] = hits.t[clear]
        todo = todo[clear]
    T[:, todo] = 0.0
    return T


def hit_materials(scene: Scene, hits: Hits) -> np.ndarray:
    """The material of each hit (a csg's child may have its own)."""
    out = np.empty(len(hits.t), dtype=np.int64)
    for k in np.unique(hits.obj):
        rows = hits.obj == k
        out[rows] = scene.objects[k].shape.material_of(hits.prim[rows], scene.objects[k].material)
    return out


def surface(scene: Scene, rays: Rays, hits: Hits) -> Surface:
    """The surface record of rays that hit (notes 000 11.6): normals by A^-T n, (u, v), T."""
    n = len(rays)
    p = rays.at(hits.t)
    normal, geometric = np.empty((3, n)), np.empty((3, n))
    material, texture = np.empty(n, dtype=np.int64), np.ones((3, n))
    batched = scene.accel.batched(hits.obj) if scene.accel is not None else np.zeros(n, dtype=bool)
    if batched.any():                                    # untransformed spheres, all at once
        rows = np.flatnonzero(batched)
        scene.accel.sphere_surface(scene, p[:, rows], hits.obj[rows], rows, normal, geometric, material, texture)
    for k in np.flatnonzero(np.bincount(hits.obj[~batched], minlength=len(scene.objects))):
        rows = np.flatnonzero((hits.obj == k) & ~batched)
        _object_surface(scene, scene.objects[k], rays, hits, rows, normal, geometric, material, texture)
    with np.errstate(invalid="ignore"):
        nx, ny, nz, gx, gy, gz, entering = facing(*rays.d, *normal, *geometric)
    return Surface(p, np.array([nx, ny, nz]), np.array([gx, gy, gz]), entering, hits.obj, material, texture,
                   lifts(scene, rays, hits) if scene.settings.shadow_terminator == "offset" else None)


def lifts(scene: Scene, rays: Rays, hits: Hits) -> np.ndarray:
    """(3, n) each hit's shadow-terminator shift (the triangle's `terminator` kernel, taken to world
    space as a vector): nonzero on smooth triangles and meshes only (docs/scene-format.md)."""
    out = np.zeros((3, len(rays)))
    for k in np.unique(hits.obj):
        obj = scene.objects[k]
        if not isinstance(obj.shape, (Triangle, Mesh)) or obj.shape.row[SMOOTH] == 0:
            continue
        rows = np.flatnonzero(hits.obj == k)
        o_obj, d_obj = to_object(obj, rays.o[:, rows], rays.d[:, rows])
        shift = terminator(obj.shape.row, obj.shape.pool, hits.prim[rows], *(o_obj + hits.t[rows] * d_obj))
        if obj.transform is not None:
            shift = linear(obj.transform, WORLD, *shift)
        out[:, rows] = np.broadcast_arrays(*shift, rows)[:3]
    return out


def _object_surface(scene, obj, rays, hits, rows, normal, geometric, material, texture) -> None:
    """Fill the surface arrays at `rows`, all hits on one object."""
    o_obj, d_obj = to_object(obj, rays.o[:, rows], rays.d[:, rows])
    p_obj = o_obj + hits.t[rows] * d_obj
    prim = hits.prim[rows]
    ns, ng = obj.shape.normals_at(p_obj, prim)
    mat = obj.shape.material_of(prim, obj.material)
    if obj.transform is not None:
        ns, ng = normal_to_world(obj.transform, 0, *ns), normal_to_world(obj.transform, 0, *ng)
    with np.errstate(invalid="ignore", divide="ignore"):
        normal[:, rows], geometric[:, rows], material[rows] = unit(*ns), unit(*ng), mat
    fill_texture(scene, obj.shape.texture_points(p_obj, prim), lambda sel: obj.shape.uv_at(p_obj[:, sel], prim[sel]),
                 mat, texture, rows)


def uv_at_hits(scene: Scene, rays: Rays, hits: Hits) -> np.ndarray:
    """(2, n) the texture coordinates (u, v) of each hit, whether or not its material has a texture."""
    uv = np.empty((2, len(rays)))
    for k in np.unique(hits.obj):
        rows = np.flatnonzero(hits.obj == k)
        obj = scene.objects[k]
        o_obj, d_obj = to_object(obj, rays.o[:, rows], rays.d[:, rows])
        u, v = obj.shape.uv_at(o_obj + hits.t[rows] * d_obj, hits.prim[rows])
        uv[:, rows] = np.broadcast_arrays(u, v, rows)[:2]
    return uv


def fill_texture(scene, p_obj, uv_of, mat, texture, rows) -> None:
    """Fill texture[:, rows] for the textured materials among `mat`; uv_of(selection) gives (u, v)."""
    table = scene.materials
    for m in table.textured:
        sel = mat == m
        if sel.any():
            tex = table.texture[m]
            u, v = uv_of(sel) if tex[KIND] == IMAGE else (0.0, 0.0)
            with np.errstate(invalid="ignore"):
                color = texture_color(tex, table.texels, *p_obj[:, sel], u, v)
            texture[:, rows[sel]] = np.array(np.broadcast_arrays(*color, p_obj[0, sel]))[:3]
