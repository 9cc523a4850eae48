"""A scene's objects: one by one, and blocks of plain spheres kept as arrays.

A particle cloud of a million spheres would cost a SceneObject and a Sphere each
(seconds to make, a gigabyte to keep). A `SphereBlock` (shapes/sphere_block.py) keeps such a run of spheres
(no transform, no name) as arrays: their rows as the sphere kernels read them
(center, r, r^2), their materials and where each is written. `ObjectList` is the
scene's sequence of objects: indexing or iterating it gives SceneObjects as before,
a block's made when asked for; the code that reads every object (the boxes, the
engines' packing, `validate`) reads the blocks' arrays instead (`sphere_blocks`, `singles`).
Object ids stay 1, 2, 3 ... in order, a block's included.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from rtcli.core.transform import Transform, outer_bounds


@dataclass(slots=True)
class SceneObject:
    id: int                          # 1, 2, 3 ... in file order (signature ids)
    name: str
    shape: object                    # a shape of rtcli.shapes, in object space
    material: int                    # row of the scene's MaterialTable
    world_from_object: Transform | None = None     # None: object space is world space
    kind: str = ""                   # the YAML shape name, for legends
    where: str = ""                  # where the scene file gives it, 'file:line:col: key.path', for messages
    transform: np.ndarray | None = field(init=False, repr=False)   # packed for the kernels (core/transform.py)

    def __post_init__(self):
        self.transform = None if self.world_from_object is None else self.world_from_object.packed

    def bounds(self) -> tuple[np.ndarray, np.ndarray] | None:
        """World-space box, or None when unbounded."""
        return outer_bounds(self.world_from_object, self.shape.bounds())


class ObjectList(Sequence):
    """The scene's objects in id order: SceneObjects one by one, and SphereBlocks."""

    def __init__(self, objects=()):
        self._starts: list[int] = []            # where each part starts
        self._parts: list = []                  # list of SceneObjects, or a SphereBlock
        self._n = 0
        for o in objects:
            self.append(o)

    def append(self, o: SceneObject) -> None:
        if not self._parts or type(self._parts[-1]) is not list:
            self._starts.append(self._n)
            self._parts.append([])
        self._parts[-1].append(o)
        self._n += 1

    def add_block(self, block) -> None:
        """Append the block's spheres (ids from len(self) + 1 on): a SphereBlock (shapes/sphere_block.py)."""
        if len(block):
            self._starts.append(self._n)
            self._parts.append(block)
            self._n += len(block)

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(self._n))]
        k = int(k)
        if k < 0:
            k += self._n
        if not 0 <= k < self._n:
            raise IndexError("object index out of range")
        p = bisect.bisect_right(self._starts, k) - 1
        part, j = self._parts[p], k - self._starts[p]
        return part[j] if type(part) is list else part.object(j, k + 1)

    def __iter__(self):
        for start, part in zip(self._starts, self._parts):
            if type(part) is list:
                yield from part
            else:
                for j in range(len(part)):
                    yield part.object(j, start + j + 1)

    def __reduce__(self):
        return _rebuilt, (self._starts, self._parts, self._n)


def _rebuilt(starts, parts, n) -> ObjectList:
    objects = ObjectList()
    objects._starts, objects._parts, objects._n = starts, parts, n
    return objects


def sphere_blocks(objects) -> list[tuple[int, object]]:
    """(index of its first sphere, block) of each SphereBlock of a scene's objects."""
    if type(objects) is not ObjectList:
        return []
    return [(s, p) for s, p in zip(objects._starts, objects._parts) if type(p) is not list]


def singles(objects):
    """(index, SceneObject) of each object not in a block."""
    if type(objects) is not ObjectList:
        yield from enumerate(objects)
        return
    for start, part in zip(objects._starts, objects._parts):
        if type(part) is list:
            yield from enumerate(part, start)


def single_objects(objects) -> list:
    """The objects not in a block."""
    return [o for _, o in singles(objects)]


def object_ids(objects) -> np.ndarray:
    """(N + 1,) uint16: each object's id by index, then 0 (what a miss, index -1, shows)."""
    ids = np.zeros(len(objects) + 1, dtype=np.uint16)
    for k, o in singles(objects):
        ids[k] = o.id
    for start, block in sphere_blocks(objects):
        ids[start:start + len(block)] = np.arange(start + 1, start + len(block) + 1)
    return ids


def object_materials(objects) -> np.ndarray:
    """(N,) int64: each object's row of the MaterialTable."""
    rows = np.zeros(len(objects), dtype=np.int64)
    for k, o in singles(objects):
        rows[k] = o.material
    for start, block in sphere_blocks(objects):
        rows[start:start + len(block)] = block.material
    return rows


def kind_counts(objects) -> dict[str, int]:
    """How many objects of each kind (the YAML shape name), in order of first appearance."""
    counts: dict[str, int] = {}
    for start, part in zip(objects._starts, objects._parts) if type(objects) is ObjectList else [(0, objects)]:
        if type(part) is not list:                       # a SphereBlock
            counts["sphere"] = counts.get("sphere", 0) + len(part)
            continue
        for o in part:
            counts[o.kind] = counts.get(o.kind, 0) + 1
    return counts
