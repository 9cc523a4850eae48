"""Constructive solid geometry: union, intersection and difference of solids (notes 002).

Each child reports the intervals of each ray that lie inside it (its hit list,
with isEntering: a span's start enters, its end leaves). The CSG merges all
children's boundaries in order of t, tracks which children each stretch of the
ray is inside, and keeps the boundaries where the boolean result switches (Roth's
ray casting of solids, with span lists). Normals of carved surfaces (a difference's
later children) are flipped, so they point out of the result. Children keep their
own transform and material.

YAML: `csg: {difference: [object, object, ...]}` (or `union:` / `intersection:`);
children are objects (with `transform:` and `material:`, no `name` needed);
difference = first child minus all the others. Children must be solids: sphere,
plane (the half-space behind its normal), box, cylinder, cone, torus or csg.
A checker is evaluated in the own space of the leaf hit (the child's, before its transform),
as for a group's child, whether the material is the child's or the csg's.

The span algebra is written once, for both engines: a span's two boundaries
(`boundaries`), their order along the ray (`precedes`) and the boolean rule
(`classify`) are kernels; the numpy engine applies them to whole arrays of rays (a
sort and a cumulative sum, `CSG.spans_of`), the compiled engine one ray at a time,
with `combine` merging span lists held in a fixed scratch buffer (the tree packed
as a postfix program: rtcli/compiled/pack.py, query.py). A CSG has no row of its
own: it answers the numpy engine's methods (Shape.hits, ...) from its children's
kernels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.transform import (
    OBJECT,
    Transform,
    affine,
    linear,
    normal_to_world,
    outer_bounds,
)
from rtcli.shapes.base import Shape
from rtcli.kernels.variants import INF, kernel, per_ray, select

OPS = ("union", "intersection", "difference")
UNION, INTERSECTION, DIFFERENCE = range(3)           # OPS's codes (the compiled program's too)


# --- the span algebra: kernels both engines call ---
@kernel
def boundaries(t_in, t_out):
    """A span [t_in, t_out] as two boundaries of a hit list, (t, +1) entering and (t, -1) leaving;
    an empty span (t_in >= t_out, or NaN: no interval there) gives none, (inf, 0) twice."""
    valid = t_in < t_out
    return select(valid, t_in, INF), select(valid, 1, 0), select(valid, t_out, INF), select(valid, -1, 0)


@kernel
def precedes(t1, delta1, t2, delta2):
    """Whether boundary 1 comes before boundary 2 along the ray: by t, and at the same t entering
    before leaving, so two solids that touch leave no gap there. Equal ones keep their order (the
    children's, then each child's entries before its exits)."""
    return (t1 < t2) | ((t1 == t2) & (delta1 > delta2))


@kernel
def classify(op, inside, first, children):
    """Whether a stretch of the ray lies in op(children), when it lies in `inside` of the
    `children` (`first`: in the first one): union any, intersection all, difference the first
    and no other."""
    if op == UNION:
        return inside > 0
    if op == INTERSECTION:
        return inside == children
    return first & (inside == 1)


@per_ray(inline=True)
def sorted_in(t, delta, owner, ident, et, ed, eo, ei, e):
    """Boundary (t, delta) of child `owner` (`ident`: its leaf and surface) put among the e sorted
    ones in et, ed, eo, ei by insertion (stable: it goes after the equal ones); returns e + 1."""
    k = e
    while k > 0 and precedes(t, delta, et[k - 1], ed[k - 1]):
        et[k], ed[k], eo[k], ei[k] = et[k - 1], ed[k - 1], eo[k - 1], ei[k - 1]
        k -= 1
    et[k], ed[k], eo[k], ei[k] = t, delta, owner, ident
    return e + 1


@per_ray
def combine(op, n, bt, bid, lists, top, et, ed, eo, ei, counts):
    """One ray's span lists of the n children of an op(children) node merged into the node's list
    (Roth: the children's boundaries in order along the ray, a count of the children each stretch is
    inside, a boundary of the result wherever `classify` changes).

    A list is boundaries in bt (t) and bid (which leaf and surface): entering, leaving, entering...;
    lists[2 j], lists[2 j + 1] are list j's start and length, lists top - n ... top - 1 the
    children's, one after another. The node's list replaces them (it is never longer); the new top
    is returned. et, ed, eo, ei hold the sorted boundaries, counts one count per child: scratch."""
    first = top - n
    start, e = lists[2 * first], 0
    for c in range(n):
        counts[c] = 0
        at, length = lists[2 * (first + c)], lists[2 * (first + c) + 1]
        for j in range(at, at + length, 2):                    # entries first, then exits (the numpy
            t_in, d_in, t_out, d_out = boundaries(bt[j], bt[j + 1])       # engine's order of ties)
            if d_in != 0:
                e = sorted_in(t_in, d_in, c, bid[j], et, ed, eo, ei, e)
        for j in range(at, at + length, 2):
            t_in, d_in, t_out, d_out = boundaries(bt[j], bt[j + 1])
            if d_out != 0:
                e = sorted_in(t_out, d_out, c, bid[j + 1], et, ed, eo, ei, e)
    inside, first_inside, now, out = 0, False, False, start
    for k in range(e):
        c = eo[k]
        was = counts[c] > 0
        counts[c] += ed[k]
        if (counts[c] > 0) != was:
            inside += -1 if was else 1
            if c == 0:
                first_inside = not was
        after = classify(op, inside, first_inside, n)
        if after != now:
            if out > start and bt[out - 1] == et[k]:        # a span or gap of length 0: both go
                out -= 1
            else:
                bt[out], bid[out], out = et[k], ei[k], out + 1
            now = after
    lists[2 * first + 1] = out - start
    return first + 1


@per_ray(inline=True)
def nearest(bt, bid, start, length, t_min, t_max):
    """(t, ident) of the first boundary of a list in (t_min, t_max), inf if none: entering ones
    first, then leaving ones, the first of equals (as the numpy engine's argmin)."""
    best, won = INF, 0
    for half in range(2):
        for j in range(start + half, start + length, 2):
            if bt[j] > t_min and bt[j] < t_max and bt[j] < best:
                best, won = bt[j], bid[j]
    return best, won


@dataclass(frozen=True)
class Child:
    shape: Shape
    transform: Transform | None     # csg_from_child; None when the child is in csg space
    material: int

    def to_child(self, o, d):
        """Rays (3, n) into the child's space."""
        if self.transform is None:
            return o, d
        m = self.transform.packed
        return np.array(affine(m, OBJECT, *o)), np.array(linear(m, OBJECT, *d))


class CSG(Shape):
    kernels = None

    def __init__(self, op: str, children: list[Child]):
        if op not in OPS:
            raise ValueError(f"unknown csg operation {op!r}")
        self.op, self.children = op, list(children)

    @property
    def solid(self) -> bool:
        return True

    def _events(self, o, d):
        """All children's span boundaries: t (n, E), +1/-1 enter/leave (0: none), child (E,),
        encoded prim (n, E); each child's entries, then its exits."""
        C = len(self.children)
        ts, deltas, owners, prims = [], [], [], []
        for c, child in enumerate(self.children):
            t_in, p_in, t_out, p_out = child.shape.spans_of(*child.to_child(o, d))
            t_in, d_in, t_out, d_out = boundaries(t_in, t_out)
            ts += [t_in, t_out]
            deltas += [d_in, d_out]
            owners += [np.full(t_in.shape[1], c)] * 2
            prims += [p_in * C + c, p_out * C + c]
        return (np.concatenate(ts, axis=1), np.concatenate(deltas, axis=1),
                np.concatenate(owners), np.concatenate(prims, axis=1))

    def spans_of(self, o, d):
        t, delta, owner, prim = self._events(o, d)
        order = np.lexsort((-delta, t), axis=1)         # `precedes`' order: by t, entries first; stable
        t, delta, prim = (np.take_along_axis(a, order, axis=1) for a in (t, delta, prim))
        owner = owner[order]
        inside = np.stack([np.cumsum(np.where(owner == c, delta, 0), axis=1) > 0
                           for c in range(len(self.children))], axis=-1)
        now = classify(OPS.index(self.op), inside.sum(axis=-1), inside[..., 0], len(self.children))
        before = np.concatenate([np.zeros((o.shape[1], 1), bool), now[:, :-1]], axis=1)
        change = (now != before) & _kept(now != before, t)
        t_in, p_in = _compact(change & now, t, prim)
        t_out, p_out = _compact(change & ~now, t, prim)
        return t_in, p_in, t_out, p_out

    def hits(self, o, d, t_min, t_max):
        t_in, p_in, t_out, p_out = self.spans_of(o, d)
        t, prim = np.concatenate([t_in, t_out], axis=1), np.concatenate([p_in, p_out], axis=1)
        t = np.where((t > np.reshape(t_min, (-1, 1))) & (t < np.reshape(t_max, (-1, 1))), t, np.inf)
        k = np.argmin(t, axis=1)
        rows = np.arange(o.shape[1])
        return t[rows, k], prim[rows, k]

    def _per_child(self, p, prim, what):
        """Evaluate `what(c, child, p_child, child_prim)` -> (k, n_c) for each hit, grouped by child."""
        C = len(self.children)
        owner, child_prim = prim % C, prim // C
        out = None
        for c in np.unique(owner):
            rows = owner == c
            child = self.children[c]
            p_c = p[:, rows] if child.transform is None else np.array(affine(child.transform.packed, OBJECT,
                                                                             *p[:, rows]))
            value = np.asarray(what(c, child, p_c, child_prim[rows]))
            if out is None:
                out = np.empty(value.shape[:-1] + (p.shape[1],), value.dtype)
            out[..., rows] = value
        return out

    def normals_at(self, p, prim):
        def outward(c, child, p_c, cp):
            n, g = child.shape.normals_at(p_c, cp)
            if child.transform is not None:
                m = child.transform.packed
                n, g = np.array(normal_to_world(m, 0, *n)), np.array(normal_to_world(m, 0, *g))
            flip = -1.0 if self.op == "difference" and c > 0 else 1.0
            return np.stack([flip * n, flip * g])
        both = self._per_child(p, prim, outward)
        return both[0], both[1]

    def uv_at(self, p, prim):
        uv = self._per_child(p, prim, lambda c, child, p_c, cp: np.stack(child.shape.uv_at(p_c, cp)))
        return uv[0], uv[1]

    def texture_points(self, p, prim):
        """Each hit taken into its leaf's own space (before the leaf's `transform:`), child by child,
        where a checker is evaluated, as for any object (docs/scene-format.md, Textures)."""
        return self._per_child(p, prim, lambda c, child, p_c, cp: child.shape.texture_points(p_c, cp))

    def material_of(self, prim, default: int):
        """Each hit's material: the child's (a nested csg asks its own children).

        `default` (the object's material) is already each child's default, from the builder.
        """
        C = len(self.children)
        out = np.empty(len(prim), dtype=np.int64)
        for c in np.unique(prim % C):
            rows = prim % C == c
            child = self.children[c]
            out[rows] = child.shape.material_of(prim[rows] // C, child.material)
        return out

    def bounds(self):
        boxes = [outer_bounds(ch.transform, ch.shape.bounds()) for ch in self.children]
        if self.op == "difference":
            return boxes[0]
        finite = [b for b in boxes if b is not None]
        if self.op == "union":
            return None if len(finite) < len(boxes) else (np.min([b[0] for b in finite], axis=0),
                                                           np.max([b[1] for b in finite], axis=0))
        return None if not finite else (np.max([b[0] for b in finite], axis=0),
                                        np.min([b[1] for b in finite], axis=0))


def _kept(change, t):
    """Which changes of the result stay when spans and gaps of length 0 go (where solids share a
    face): of the changes at one t (a run of equal t along the sorted row) none when there is an
    even number, else the last, as `combine` cancels each with the one before it at the same t."""
    count = t.shape[1]
    pos = np.broadcast_to(np.arange(count), t.shape)
    starts = np.ones(t.shape, dtype=bool)
    starts[:, 1:] = t[:, 1:] != t[:, :-1]
    ends = np.ones(t.shape, dtype=bool)
    ends[:, :-1] = t[:, :-1] != t[:, 1:]
    lo = np.maximum.accumulate(np.where(starts, pos, 0), axis=1)                      # each run's first
    hi = np.minimum.accumulate(np.where(ends, pos, count)[:, ::-1], axis=1)[:, ::-1]  # and last
    done = np.cumsum(change, axis=1)
    earlier = np.take_along_axis(done, lo, axis=1) - np.take_along_axis(change, lo, axis=1)
    in_run = np.take_along_axis(done, hi, axis=1) - earlier
    return (done - earlier == in_run) & (in_run % 2 == 1)


def _compact(mask, t, prim):
    """Rows' masked entries moved to the front, padded with inf: (n, K)."""
    n = len(t)
    counts = mask.sum(axis=1)
    K = max(1, int(counts.max(initial=0)))
    out_t, out_p = np.full((n, K), np.inf), np.zeros((n, K), dtype=np.int64)
    r, c = np.nonzero(mask)
    k = (np.cumsum(mask, axis=1) - 1)[r, c]
    out_t[r, k], out_p[r, k] = t[r, c], prim[r, c]
    return out_t, out_p
