"""Rays in arrays: a wavefront of n rays S + t c, stored as components (3, n); the camera's rays
through arrays of image positions."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.camera import primary_ray


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


def camera_rays(cam, x, y, nc: int, nr: int) -> Rays:
    """The camera's rays through pixel coordinates (x, y) (n,) of an nc x nr image."""
    ox, oy, oz, *d = primary_ray(cam.row, x, y, nc, nr)
    return Rays(np.repeat(np.array([[ox], [oy], [oz]]), len(x), axis=1), np.array(d))
