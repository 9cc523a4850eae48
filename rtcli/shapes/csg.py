"""Constructive solid geometry: union, intersection and difference of solids (notes 002).

Each child reports the intervals of each ray that lie inside it (its hit list,
with isEntering: a span's start enters, its end leaves). The CSG merges all
children's boundaries in order of t, tracks which children each stretch of the
ray is inside, and keeps the boundaries where the boolean result switches.
Normals of carved surfaces (a difference's later children) are flipped, so they
point out of the result. Children keep their own transform and material.

YAML: `csg: {difference: [object, object, ...]}` (or `union:` / `intersection:`);
children are objects (with `transform:` and `material:`, no `name` needed);
difference = first child minus all the others. Children must be solids: sphere,
plane (the half-space behind its normal), box, cylinder, cone, torus or csg.
The checker texture of a csg is evaluated in the csg's own object space.

Only the numpy engine renders a CSG: merging a variable number of spans per ray
is sorting and counting over whole arrays, which numpy does at once; the compiled
engine, one ray at a time, would need per-ray lists of spans (docs/architecture.md).
So a CSG has no kernels; it answers the numpy engine's methods (Shape.hits, ...)
from its children's kernels.
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

OPS = ("union", "intersection", "difference")


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

    def _result(self, inside: np.ndarray) -> np.ndarray:
        """The boolean op on per-child inside flags (..., C)."""
        if self.op == "union":
            return inside.any(axis=-1)
        if self.op == "intersection":
            return inside.all(axis=-1)
        return inside[..., 0] & ~inside[..., 1:].any(axis=-1)

    def _events(self, o, d):
        """All children's span boundaries: t (n, E), +1/-1 enter/leave, child (E,), encoded prim (n, E)."""
        C = len(self.children)
        ts, deltas, owners, prims = [], [], [], []
        for c, child in enumerate(self.children):
            t_in, p_in, t_out, p_out = child.shape.spans_of(*child.to_child(o, d))
            valid = t_in < t_out
            ts += [np.where(valid, t_in, np.inf), np.where(valid, t_out, np.inf)]
            deltas += [valid.astype(np.int64), -valid.astype(np.int64)]
            owners += [np.full(t_in.shape[1], c)] * 2
            prims += [p_in * C + c, p_out * C + c]
        return (np.concatenate(ts, axis=1), np.concatenate(deltas, axis=1),
                np.concatenate(owners), np.concatenate(prims, axis=1))

    def spans_of(self, o, d):
        t, delta, owner, prim = self._events(o, d)
        order = np.lexsort((-delta, t), axis=1)         # by t; at equal t, entries before exits
        t, delta, prim = (np.take_along_axis(a, order, axis=1) for a in (t, delta, prim))
        owner = owner[order]
        inside = np.stack([np.cumsum(np.where(owner == c, delta, 0), axis=1) > 0
                           for c in range(len(self.children))], axis=-1)
        now = self._result(inside)
        before = np.concatenate([np.zeros((o.shape[1], 1), bool), now[:, :-1]], axis=1)
        t_in, p_in = _compact(now & ~before, t, prim)
        t_out, p_out = _compact(~now & before, t, prim)
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
