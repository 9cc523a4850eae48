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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.transform import Transform, outer_bounds, ray_into

OPS = ("union", "intersection", "difference")


@dataclass(frozen=True)
class Child:
    shape: object
    transform: Transform | None     # csg_from_child; None when the child is in csg space
    material: int

    def to_child(self, o, d):
        return ray_into(self.transform, o, d)


def csg_from(p, builder, material: int) -> "CSG":
    ops = [k for k in OPS if p.has(k)]
    if len(ops) != 1:
        raise p.error(None, "a csg needs exactly one of: union, intersection, difference")
    from rtcli.scenefile.params import as_params
    items = p.items(ops[0])
    if len(items) < 2:
        raise p.error(ops[0], f"needs at least 2 objects, got {len(items)}")
    children = []
    for item, where, path in items:
        cp = as_params(item, where, path, "an object (a mapping with a shape key)")
        shape, t, mat = builder.child(cp, material)
        if not hasattr(shape, "spans") or not getattr(shape, "capped", True):
            raise cp.error(None, "a csg child must be a solid: sphere, plane, box, "
                           "cylinder, cone (capped), torus or csg")
        children.append(Child(shape, t, mat))
    return CSG(ops[0], children)


class CSG:
    def __init__(self, op: str, children: list[Child]):
        self.op, self.children = op, list(children)

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
            t_in, p_in, t_out, p_out = child.shape.spans(*child.to_child(o, d))
            valid = t_in < t_out
            ts += [np.where(valid, t_in, np.inf), np.where(valid, t_out, np.inf)]
            deltas += [valid.astype(np.int64), -valid.astype(np.int64)]
            owners += [np.full(t_in.shape[1], c)] * 2
            prims += [p_in * C + c, p_out * C + c]
        return (np.concatenate(ts, axis=1), np.concatenate(deltas, axis=1),
                np.concatenate(owners), np.concatenate(prims, axis=1))

    def spans(self, o, d):
        t, delta, owner, prim = self._events(o, d)
        order = np.lexsort((-delta, t), axis=1)         # by t; at equal t, entries before exits
        t, delta, prim = (np.take_along_axis(a, order, axis=1) for a in (t, delta, prim))
        owner = owner[order]
        inside = np.stack([np.cumsum(np.where(owner == c, delta, 0), axis=1) > 0
                           for c in range(len(self.children))], axis=-1)
        now = self._result(inside)
        before = np.concatenate([np.zeros((len(o), 1), bool), now[:, :-1]], axis=1)
        t_in, p_in = _compact(now & ~before, t, prim)
        t_out, p_out = _compact(~now & before, t, prim)
        return t_in, p_in, t_out, p_out

    def intersect(self, o, d, t_min, t_max):
        t_in, p_in, t_out, p_out = self.spans(o, d)
        t, prim = np.concatenate([t_in, t_out], axis=1), np.concatenate([p_in, p_out], axis=1)
        t = np.where((t > np.reshape(t_min, (-1, 1))) & (t < np.reshape(t_max, (-1, 1))), t, np.inf)
        k = np.argmin(t, axis=1)
        rows = np.arange(len(o))
        return t[rows, k], prim[rows, k]

    def _per_child(self, p, prim, what):
        """Evaluate `what(child, p_child, child_prim)` for each hit, grouped by child."""
        C = len(self.children)
        owner, child_prim = prim % C, prim // C
        out = None
        for c in np.unique(owner):
            rows = owner == c
            child = self.children[c]
            p_c = p[rows] if child.transform is None else child.transform.inverse.point(p[rows])
            value = what(c, child, p_c, child_prim[rows])
            if out is None:
                out = np.empty((len(p),) + value.shape[1:], value.dtype)
            out[rows] = value
        return out

    def normal(self, p, prim):
        def outward(c, child, p_c, cp):
            n = child.shape.normal(p_c, cp)
            n = n if child.transform is None else child.transform.normal(n)
            return -n if self.op == "difference" and c > 0 else n
        return self._per_child(p, prim, outward)

    def uv(self, p, prim):
        return self._per_child(p, prim, lambda c, child, p_c, cp: child.shape.uv(p_c, cp))

    def material_of(self, prim, default: int):
        """Each hit's material: the child's (a nested csg asks its own children).

        `default` (the object's material) is already each child's default, from build.
        """
        C = len(self.children)
        out = np.empty(len(prim), dtype=np.int64)
        for c in np.unique(prim % C):
            rows = prim % C == c
            child = self.children[c]
            nested = getattr(child.shape, "material_of", None)
            out[rows] = nested(prim[rows] // C, child.material) if nested else child.material
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
