"""The compiled engine's dispatch on a shape's kind, one ray at a time: a chain of links, one per
shape of the registry (rtcli/shapes/), each calling its shape's kernel when the kind is its own and
the next link otherwise. Built when this module is imported, so adding a shape to rtcli/shapes/
adds it here too; the numpy engine dispatches by grouping rays by kind instead
(rtcli/wavefront/intersect.py).

A link is one kernel compiled once per shape with other globals bound (variants.compiled(link,
KIND_HERE=..., HIT=..., NEXT=...)): the names below stand for what each link is bound to.
"""

from __future__ import annotations

from rtcli.core.bvh import walk
from rtcli.kernels.variants import INF, compiled, per_ray, to_int
from rtcli.shapes import SHAPES
from rtcli.shapes.triangle import triangle_leaf


def _unbound(*args):
    raise TypeError("a dispatch link runs only as chain() or spans_chain() binds it")


# What chain() and spans_chain() bind in each link: the kind it answers for and the kernels it calls,
KIND_HERE, HIT, KERNEL, SPANS, STORE, STORE_NEXT, NEXT = -1, _unbound, _unbound, _unbound, _unbound, _unbound, _unbound
# a mesh's columns (its BVH's root, its first triangle), a solid's boundaries and a span's places.
ROOT_AT = FIRST_AT = BOUNDARIES = T_AT = T_IN = P_IN = T_OUT = P_OUT = 0

WALK_TRIANGLES = compiled(walk, LEAF=triangle_leaf)      # a mesh's own BVH over its triangles


@per_ray(inline=True)
def hit_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """HIT of the shape of kind KIND, else the next link's answer."""
    if kind == KIND_HERE:
        return HIT(row, g.pool, ox, oy, oz, dx, dy, dz, t_min, t_max)
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


@per_ray(inline=True)
def walk_link(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    """A shape hit through its own BVH over pool triangles (a mesh): prim is the face's index."""
    if kind == KIND_HERE:
        t, face, _ = WALK_TRIANGLES(g, to_int(row[ROOT_AT]), ox, oy, oz, dx, dy, dz, t_min, t_max,
                                    shadow, stack, bottom)
        return t, face - to_int(row[FIRST_AT])
    return NEXT(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom)


@per_ray(inline=True)
def point_link(kind, row, pool, prim, x, y, z):
    """KERNEL (normals or uv) of the shape of kind KIND at a point, else the next link's."""
    if kind == KIND_HERE:
        return KERNEL(row, pool, prim, x, y, z)
    return NEXT(kind, row, pool, prim, x, y, z)


@per_ray(inline=True)
def no_hit(kind, row, g, ox, oy, oz, dx, dy, dz, t_min, t_max, shadow, stack, bottom):
    return INF, 0


@per_ray(inline=True)
def no_normals(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0, 1.0, 0.0, 0.0, 1.0


@per_ray(inline=True)
def no_uv(kind, row, pool, prim, x, y, z):
    return 0.0, 0.0


def chain(name: str, end, **bind):
    """The dispatcher calling each registered shape's kernel `name` by kind (then `end`, with `bind`)."""
    link = compiled(end, **bind)
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


@per_ray(inline=True)
def spans_link(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride):
    """SPANS of the solid of kind KIND_HERE stored in a span list from bt[at], bid[at] (each
    boundary's id: ident + stride x its surface); how many boundaries. Else the next link's answer."""
    if kind == KIND_HERE:
        STORE(SPANS(row, pool, ox, oy, oz, dx, dy, dz), bt, bid, at, ident, stride)
        return BOUNDARIES
    return NEXT(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride)


@per_ray(inline=True)
def no_spans(kind, row, pool, ox, oy, oz, dx, dy, dz, bt, bid, at, ident, stride):
    return 0


@per_ray(inline=True)
def store_span(parts, bt, bid, at, ident, stride):
    """Span J of a spans kernel's answer (t_in, prim_in, t_out, prim_out, t_in, ...) as the list's
    boundaries 2 J and 2 J + 1, then the next spans (STORE_NEXT)."""
    bt[at + T_AT], bid[at + T_AT] = parts[T_IN], ident + stride * parts[P_IN]
    bt[at + T_AT + 1], bid[at + T_AT + 1] = parts[T_OUT], ident + stride * parts[P_OUT]
    STORE_NEXT(parts, bt, bid, at, ident, stride)


@per_ray(inline=True)
def stored(parts, bt, bid, at, ident, stride):
    return


def spans_chain():
    """SPANS_ANY: the `spans` kernel of each registered solid, by kind, into a span list."""
    link = compiled(no_spans)
    for kind, cls in reversed(list(enumerate(SHAPES.values()))):
        if cls.kernels.spans is None:
            continue
        store = compiled(stored)
        for j in reversed(range(cls.SPANS)):                 # one store per span: tuple indices are constants
            store = compiled(store_span, T_AT=2 * j, T_IN=4 * j, P_IN=4 * j + 1, T_OUT=4 * j + 2, P_OUT=4 * j + 3,
                             STORE_NEXT=store)
        link = compiled(spans_link, KIND_HERE=kind, SPANS=cls.kernels.spans, STORE=store, BOUNDARIES=2 * cls.SPANS,
                        NEXT=link)
    return link
