"""Rays in arrays: a wavefront of n rays S + t c, stored as components (3, n)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Rays:
    o: np.ndarray           # (3, n) start points S: rows x, y, z
    d: np.ndarray           # (3, n) directions c, not necessarily unit length

    @staticmethod
    def from_rows(origin, direction) -> "Rays":
        """Rays from (n, 3) arrays of origins and directions."""
        return Rays(np.ascontiguousarray(np.asarray(origin, float).reshape(-1, 3).T),
                    np.ascontiguousarray(np.asarray(direction, float).reshape(-1, 3).T))

    def __len__(self) -> int:
        return self.o.shape[1]

    def __getitem__(self, which) -> "Rays":         # a mask or an index array
        return Rays(self.o[:, which], self.d[:, which])

    def at(self, t: np.ndarray) -> np.ndarray:
        return self.o + t * self.d
