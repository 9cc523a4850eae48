"""Cameras: from continuous pixel coordinates to world-space rays (notes 000 11.2, 004).

All three forms map a sample position (x, y) in pixel units, where pixel (i, j)'s
centre is (i + 0.5, j + 0.5) and (0, 0) is the top-left corner, to a point p on
the image plane; the ray is eye + lambda (p - eye). A Camera packs that affine map
as a row of 12 floats (EYE, ORIGIN, RIGHT, DOWN), which `primary_ray` reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.elementary import cos, sin
from rtcli.core.vec import cross3, length3, unit3
from rtcli.kernels.variants import kernel

EYE, ORIGIN, RIGHT, DOWN = 0, 3, 6, 9     # offsets of the vectors in Camera.row


@kernel
def primary_ray(cam, x, y, nc, nr):
    """The ray through pixel coordinates (x, y) of an nc x nr image: from the eye to
    p = origin + (x / nc) right + (y / nr) down. Returns (ox, oy, oz, dx, dy, dz)."""
    a, b = x / nc, y / nr
    px = cam[ORIGIN] + a * cam[RIGHT] + b * cam[DOWN]
    py = cam[ORIGIN + 1] + a * cam[RIGHT + 1] + b * cam[DOWN + 1]
    pz = cam[ORIGIN + 2] + a * cam[RIGHT + 2] + b * cam[DOWN + 2]
    return cam[EYE], cam[EYE + 1], cam[EYE + 2], px - cam[EYE], py - cam[EYE + 1], pz - cam[EYE + 2]


def eye_basis(eye, look_at, up) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, w): w toward look_at, u = w x up to the right, v = u x w up. ValueError if degenerate."""
    w = np.asarray(look_at, float) - np.asarray(eye, float)
    if length3(w) == 0:
        raise ValueError("look_at must differ from eye")
    w = unit3(w)
    side = cross3(w, np.asarray(up, float))
    if length3(side) <= 1e-9 * length3(up):
        raise ValueError("up must not be parallel to the view direction")
    u = unit3(side)
    return u, cross3(u, w), w


@dataclass(frozen=True)
class Camera:
    """p(x, y) = origin + (x / nc) * right + (y / nr) * down, an affine map of pixel coordinates."""

    eye: np.ndarray
    origin: np.ndarray      # image-plane point at pixel coordinates (0, 0)
    right: np.ndarray       # change of p over the whole image width (x: 0 -> nc)
    down: np.ndarray        # change of p over the whole image height (y: 0 -> nr)

    @property
    def row(self) -> np.ndarray:
        return np.concatenate([self.eye, self.origin, self.right, self.down]).astype(float)


def from_fov(eye, look_at, up, fov: float, nc: int, nr: int) -> Camera:
    """Vertical field of view `fov` in degrees; the width follows the image's aspect."""
    u, v, w = eye_basis(eye, look_at, up)
    angle = np.radians(fov) / 2
    half_h = float(sin(angle) / cos(angle))                     # tan(fov / 2)
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
