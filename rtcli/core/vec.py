"""Vectors as components (x, y, z): the few operations the notes use, written once.

The kernels take and return components that are floats or (n,) arrays (see
rtcli/kernels/variants.py). `dot3`, `cross3`, `unit3` and `length3` apply them to (..., 3)
arrays, for setting up shapes and cameras.
"""

from __future__ import annotations

import numpy as np

from rtcli.kernels.variants import kernel, maximum, sqrt


@kernel
def dot(ax, ay, az, bx, by, bz):
    """a.b, summed x + y + z in this order (every row of a batch the same way)."""
    return ax * bx + ay * by + az * bz


@kernel
def cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@kernel
def unit(x, y, z):
    """The vector divided by its length."""
    length = sqrt(x * x + y * y + z * z)
    return x / length, y / length, z / length


@kernel
def reflect(dx, dy, dz, nx, ny, nz):
    """Mirror direction d - 2(d.n)n for unit n (notes 000, 11.7.1)."""
    dn = 2 * dot(dx, dy, dz, nx, ny, nz)
    return dx - dn * nx, dy - dn * ny, dz - dn * nz


@kernel
def refract(dx, dy, dz, nx, ny, nz, eta):
    """Snell's law for unit d and unit n facing against d, eta = n1/n2 (notes 000, 11.7.3).

    Returns (tx, ty, tz, tir): the unit refracted direction, and whether the ray is
    past the critical angle (total internal reflection), where t is meaningless.
    """
    cos_i = -dot(dx, dy, dz, nx, ny, nz)                 # cos theta_1 >= 0
    k = 1 - eta * eta * (1 - cos_i * cos_i)              # cos^2 theta_2
    b = eta * cos_i - sqrt(maximum(k, 0.0))
    tx, ty, tz = unit(eta * dx + b * nx, eta * dy + b * ny, eta * dz + b * nz)
    return tx, ty, tz, k < 0


# --- the same on (..., 3) arrays, for setup code ---
def split(a) -> tuple:
    a = np.asarray(a, dtype=float)
    return a[..., 0], a[..., 1], a[..., 2]


def stack(x, y, z) -> np.ndarray:
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def dot3(a, b) -> np.ndarray:
    return dot(*split(a), *split(b))


def length3(a) -> np.ndarray:
    return np.sqrt(dot3(a, a))


def unit3(a) -> np.ndarray:
    return stack(*unit(*split(a)))


def cross3(a, b) -> np.ndarray:
    return stack(*cross(*split(a), *split(b)))
