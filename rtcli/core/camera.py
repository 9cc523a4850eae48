"""Cameras: from continuous pixel coordinates to world-space rays (notes 000 11.2, 004).

All three forms map a sample position (x, y) in pixel units, where pixel (i, j)'s
centre is (i + 0.5, j + 0.5) and (0, 0) is the top-left corner, to a point p on
the image plane; the ray is eye + lambda (p - eye).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.vec import cross, normalize
from rtcli.wavefront.rays import Rays


def eye_basis(eye, look_at, up) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, w): w toward look_at, u = w x up to the right, v = u x w up. ValueError if degenerate."""
    w = np.asarray(look_at, float) - np.asarray(eye, float)
    if np.linalg.norm(w) == 0:
        raise ValueError("look_at must differ from eye")
    w = normalize(w)
    side = cross(w, np.asarray(up, float))
    if np.linalg.norm(side) <= 1e-9 * np.linalg.norm(up):
        raise ValueError("up must not be parallel to the view direction")
    u = normalize(side)
    return u, cross(u, w), w


@dataclass(frozen=True)
class Camera:
    """p(x, y) = origin + (x / nc) * right + (y / nr) * down, an affine map of pixel coordinates."""

    eye: np.ndarray
    origin: np.ndarray      # image-plane point at pixel coordinates (0, 0)
    right: np.ndarray       # change of p over the whole image width (x: 0 -> nc)
    down: np.ndarray        # change of p over the whole image height (y: 0 -> nr)

    def rays(self, x: np.ndarray, y: np.ndarray, nc: int, nr: int) -> Rays:
        p = (self.origin + (x / nc)[:, None] * self.right + (y / nr)[:, None] * self.down)
        return Rays(np.broadcast_to(self.eye, p.shape).copy(), p - self.eye)


def from_fov(eye, look_at, up, fov: float, nc: int, nr: int) -> Camera:
    """Vertical field of view `fov` in degrees; the width follows the image's aspect."""
    u, v, w = eye_basis(eye, look_at, up)
    half_h = np.tan(np.radians(fov) / 2)
    half_w = half_h * nc / nr
    corner = np.asarray(eye, float) + w - half_w * u + half_h * v
    return Camera(np.asarray(eye, float), corner, 2 * half_w * u, -2 * half_h * v)


def from_window(eye, look_at, up, focal: float, wl, wr, wt, wb, nc: int, nr: int) -> Camera:
    """Notes 000 11.2: pixel (i, j) -> (wl + i du, wt + j dv, f), du = (wr-wl)/(nc-1), dv = (wb-wt)/(nr-1).

    Sample x = i + 0.5 lands on column i's point, so the first and last columns sit
    exactly on the window's edges. A single column or row sits at the window's middle.
    """
    u, v, w = eye_basis(eye, look_at, up)
    du = (wr - wl) / (nc - 1) if nc > 1 else 0.0
    dv = (wb - wt) / (nr - 1) if nr > 1 else 0.0
    x0 = wl - 0.5 * du if nc > 1 else (wl + wr) / 2          # eye-space x at pixel coordinate 0
    y0 = wt - 0.5 * dv if nr > 1 else (wt + wb) / 2
    eye = np.asarray(eye, float)
    return Camera(eye, eye + x0 * u + y0 * v + focal * w, nc * du * u, nr * dv * v)


def from_screen(eye, lower_left, horizontal, vertical, nc: int, nr: int) -> Camera:
    """Notes 004: p = lower_left + (i+0.5)/nc horizontal + (1 - (j+0.5)/nr) vertical."""
    ll, h, vv = (np.asarray(a, float) for a in (lower_left, horizontal, vertical))
    return Camera(np.asarray(eye, float), ll + vv, h, -vv)
