"""Vector helpers on (..., 3) arrays: the few operations the notes use."""

from __future__ import annotations

import numpy as np


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a.b, written out so every row is computed the same way in any batch."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def length(a: np.ndarray) -> np.ndarray:
    return np.sqrt(dot(a, a))


def normalize(a: np.ndarray) -> np.ndarray:
    return a / length(a)[..., None]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def reflect(d: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Mirror direction d - 2(d.n)n for unit n (notes 000, 11.7.1)."""
    return d - 2 * dot(d, n)[..., None] * n


def refract(d: np.ndarray, n: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Snell's law for unit d and unit n facing against d, eta = n1/n2 (notes 000, 11.7.3).

    Returns (t, tir): the unit refracted direction, and a mask of rays past the
    critical angle (total internal reflection), whose t is meaningless.
    """
    cos_i = -dot(d, n)                                   # cos theta_1 >= 0
    k = 1 - eta * eta * (1 - cos_i * cos_i)              # cos^2 theta_2
    tir = k < 0
    cos_t = np.sqrt(np.maximum(k, 0))
    t = eta[..., None] * d + (eta * cos_i - cos_t)[..., None] * n
    return normalize(t), tir
