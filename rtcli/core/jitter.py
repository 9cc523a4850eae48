"""Deterministic 'random' numbers: a hash of the inputs, not a generator's state.

A sample's jitter depends only on what it is for (a pixel and sample index, a
hit point), never on which tile or worker computed it, so an image is
bit-identical for any tile size or worker count.
"""

from __future__ import annotations

import numpy as np

_M1, _M2 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finalizer: a well-mixed 64-bit hash of x."""
    x = (x ^ (x >> np.uint64(30))) * _M1
    x = (x ^ (x >> np.uint64(27))) * _M2
    return x ^ (x >> np.uint64(31))


def uniform(*keys: np.ndarray) -> np.ndarray:
    """Uniform numbers in [0, 1), one per row of the broadcast keys (ints or floats)."""
    h = np.uint64(0x9E3779B97F4A7C15)
    with np.errstate(over="ignore"):
        for k in keys:
            k = np.asarray(k)
            bits = k.view(np.uint64) if k.dtype == np.float64 else k.astype(np.uint64)
            h = _mix(h ^ bits) + np.uint64(0x9E3779B97F4A7C15)
        h = _mix(h)
    return (h >> np.uint64(11)).astype(np.float64) * (1.0 / (1 << 53))
