"""Rays in arrays: a wavefront of n rays S + t c."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Rays:
    origin: np.ndarray      # (n, 3) start points S
    direction: np.ndarray   # (n, 3) directions c, not necessarily unit length

    def __len__(self) -> int:
        return len(self.origin)

    def __getitem__(self, which) -> "Rays":         # a mask or an index array
        return Rays(self.origin[which], self.direction[which])

    def at(self, t: np.ndarray) -> np.ndarray:
        return self.origin + t[:, None] * self.direction
