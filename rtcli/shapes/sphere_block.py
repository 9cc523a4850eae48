"""A run of plain spheres kept as arrays: a block of a scene's objects (core/objects.py,
ObjectList), each sphere made a SceneObject only when asked for."""

from __future__ import annotations

import numpy as np

from rtcli.core.objects import SceneObject
from rtcli.errors import Where
from rtcli.shapes.sphere import Sphere


class SphereBlock:
    """n plain spheres: `rows` (n, 5) center, r, r^2; `material` (n,) rows of the MaterialTable;
    where each is written, for messages: `file`, `lines` (n,) and `column` (0: no place, an array's
    spheres), and `path` with `first`: sphere j is `path[first + j]`."""

    __slots__ = ("rows", "material", "file", "lines", "column", "path", "first")

    def __init__(self, centers, radii, material, file: str = "", lines=None, column: int = 0,
                 path: str = "spheres", first: int = 0):
        centers, radii = np.asarray(centers, dtype=float), np.asarray(radii, dtype=float)
        self.rows = np.empty((len(radii), 5))
        self.rows[:, :3], self.rows[:, 3], self.rows[:, 4] = centers, radii, radii * radii
        self.material = np.broadcast_to(np.asarray(material, dtype=np.int64), (len(radii),))
        self.file, self.column, self.path, self.first = file, column, path, first
        self.lines = lines

    def __len__(self) -> int:
        return len(self.rows)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) each (n, 3): the spheres' boxes, as Sphere.bounds gives them one by one."""
        c, r = self.rows[:, :3], self.rows[:, 3:4]
        return c - r, c + r

    def where(self, j: int) -> str:
        """'file:line:col: path[k]' of sphere j, as a SceneObject's `where`."""
        label = f"{self.path}[{self.first + j}]"
        if self.lines is None:
            return f"{self.file}: {label}" if self.file else label
        return f"{Where(self.file, int(self.lines[j]), self.column)}: {label}"

    def object(self, j: int, id: int) -> SceneObject:
        """Sphere j as a SceneObject with id `id` (made now: kept nowhere)."""
        shape = Sphere.__new__(Sphere)
        shape.row = self.rows[j].copy()
        return SceneObject(id, "", shape, int(self.material[j]), None, "sphere", self.where(j))
