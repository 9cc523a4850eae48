"""Ray-scene queries of the compiled engine, one ray at a time: the nearest hit and shadow feelers.

The same questions as rtcli/wavefront/intersect.py asks for arrays of rays. The
listed objects (planes, or all objects of a scene without a BVH) are tested
one by one, the others through the scene's BVH, meshes through their own BVH (two
levels): one walk (rtcli/core/bvh.py), specialised here for scene objects and for
triangles. A tie (two objects hit at the very same t, say coplanar faces) goes to the
first listed object, as in the numpy engine; between two objects of a BVH it may go
to the other one than the numpy engine's level-by-level walk picks.

Which shape's kernel to call is decided by the object's KIND, through a chain of
tests built from the registry when this module is imported (`chain`): adding a shape
to rtcli/shapes/ adds it here too. This module compiles with numba: import it only
when numba is installed.
"""

from __future__ import annotations

from rtcli.compiled.pack import CASTS, KIND, XFORM
from rtcli.core.bvh import ANY_CASTER, CHILD, COUNT, NEAREST, walk, walk_rays
from rtcli.core.transform import ray_to_object
from rtcli.shapes import SHAPES
from rtcli.shapes.triangle import triangle_leaf
from rtcli.variants import INF, compiled, per_ray, to_int


# --- the dispatch on the shape's kind: one link per registered shape ---
@per_ray(inline=True)
def hit_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """HIT of the shape of kind KIND, else the next link's answer."""
    if kind == KIND_HERE:                                                           # noqa: F821
        return HIT(row, g.pool, ox, oy, oz, dx, dy, dz, t_min, t_max)                # noqa: F821
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)  # noqa: F821


@per_ray(inline=True)
def walk_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A shape hit through its own BVH over pool triangles (a mesh): prim is the face's index."""
    if kind == KIND_HERE:                                                           # noqa: F821
        t, face, _ = WALK_TRIANGLES(g, to_int(row[ROOT_AT]), ox, oy, oz, dx, dy, dz, t_min, t_max,  # noqa: F821
                                    shadow, stack, bottom)
        return t, face - to_int(row[FIRST_AT])                                      # noqa: F821
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)  # noqa: F821


@per_ray(inline=True)
def point_link(kind, row, pool, prim, x, y, z):
    """KERNEL (normals or uv) of the shape of kind KIND at a point, else the next link's."""
    if kind == KIND_HERE:                                                           # noqa: F821
        return KERNEL(row, pool, prim, x, y, z)                                      # noqa: F821
    return NEXT(kind, row, pool, prim, x, y, z)                                      # noqa: F821


@per_ray(inline=True)
def no_hit(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    return INF, 0


@per_ray(inline=True)
def no_normals(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0, 1.0, 0.0, 0.0, 1.0


@per_ray(inline=True)
def no_uv(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0


def chain(name: str, end):
    """The dispatcher calling each registered shape's kernel `name` by kind."""
    link = compiled(end)
    for kind, cls in reversed(list(enumerate(SHAPES.values()))):
        kernel = getattr(cls.kernels, name)
        if name == "hit" and kernel is None:
            link = compiled(walk_link, KIND_HERE=kind, NEXT=link, ROOT_AT=cls.ROOT_COLUMN,
                                FIRST_AT=cls.FIRST_COLUMN)
        elif name == "hit":
            link = compiled(hit_link, KIND_HERE=kind, HIT=kernel, NEXT=link)
        else:
            link = compiled(point_link, KIND_HERE=kind, KERNEL=kernel, NEXT=link)
    return link


WALK_TRIANGLES = compiled(walk, LEAF=triangle_leaf)
HIT_ANY, NORMALS_ANY, UV_ANY = chain("hit", no_hit), chain("normals", no_normals), chain("uv", no_uv)


# --- objects and the scene ---
@per_ray(inline=True)
def object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """(t, prim) of scene object k for a world-space ray: the ray taken into object space
    (notes 000 11.3.4), then its shape's hit."""
    x = g.ints[k, XFORM]
    if x >= 0:
        ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
    return HIT_ANY(g.ints[k, KIND], g.objects[k], g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


@per_ray(inline=True)
def object_leaf(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A leaf entry of the scene's tree: object k (skipped by a feeler if it casts no shadow)."""
    if shadow != NEAREST and g.ints[k, CASTS] == 0:
        return INF, 0
    return object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


WALK_OBJECTS = compiled(walk, LEAF=object_leaf)


@per_ray(inline=True)
def scene_hit(g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack):
    """(t, object, prim): the nearest hit in (t_min, t_max); with `shadow` (a mode of
    core/bvh.py) among the objects that cast shadows, any (ANY_CASTER) or the nearest; object -1
    on a miss. stack: scratch for both tree levels."""
    best, obj, prim = t_max, -1, 0
    for j in range(len(g.listed)):
        k = g.listed[j]
        if shadow != NEAREST and g.ints[k, CASTS] == 0:
            continue
        t, p = object_hit(g, k, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, 0)
        if t < best:
            best, obj, prim = t, k, p
            if shadow == ANY_CASTER:
                return best, obj, prim
    if g.links[0, CHILD] < 0 and g.links[0, COUNT] == 0:          # no tree (a scene of few objects)
        return best, obj, prim
    t, k, p = WALK_OBJECTS(g, 0, ox, oy, oz, dx, dy, dz, t_min, best, shadow, stack, 0)
    if k >= 0:
        return t, k, p
    return best, obj, prim


# --- for the numpy engine: the same walks over arrays of rays ---
WALK_RAYS_TRIANGLES = compiled(walk_rays, WALK=WALK_TRIANGLES)
WALK_RAYS_OBJECTS = compiled(walk_rays, WALK=WALK_OBJECTS)
