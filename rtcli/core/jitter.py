"""Deterministic 'random' numbers: a hash of the inputs, not a generator's state.

A sample's jitter depends only on what it is for (a pixel and sample index, a
hit point), never on which tile or worker computed it, so an image is
bit-identical for any tile size or worker count. The hash is splitmix64's
finalizer, fed one 64-bit key at a time (a float's bits, or an integer).
"""

from __future__ import annotations

import numpy as np

from rtcli.kernels.variants import bits, kernel, u64

GOLDEN = np.uint64(0x9E3779B97F4A7C15)
M1, M2 = np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB)
S11, S27, S30, S31 = np.uint64(11), np.uint64(27), np.uint64(30), np.uint64(31)


@kernel
def mix(x):
    """splitmix64's finalizer: a well-mixed 64-bit hash of x (uint64 arithmetic wraps)."""
    x = (x ^ (x >> S30)) * M1
    x = (x ^ (x >> S27)) * M2
    return x ^ (x >> S31)


@kernel
def absorb(h, key):
    """The hash state h after taking in one more 64-bit key."""
    return mix(h ^ key) + GOLDEN


@kernel
def to_unit(h):
    """A uniform number in [0, 1) from the state: its top 53 bits."""
    return (mix(h) >> S11) * (1.0 / (1 << 53))


@kernel
def hash_pixel(i, j, cell, axis):
    """Jitter of sample `cell` of pixel (i, j) along `axis` (0: x, 1: y), in [0, 1)."""
    h = absorb(absorb(GOLDEN, u64(i)), u64(j))
    return to_unit(absorb(absorb(h, u64(cell)), u64(axis)))


@kernel
def hash_point(x, y, z, cell, axis):
    """Jitter of cell `cell` along `axis` seen from the point (x, y, z), in [0, 1)."""
    h = absorb(absorb(absorb(GOLDEN, bits(x)), bits(y)), bits(z))
    return to_unit(absorb(absorb(h, u64(cell)), u64(axis)))


def sample_positions(i: np.ndarray, j: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n stratified, jittered sample positions per pixel, shape (n*n, len(i)) each.

    With n = 1 the single sample is the pixel centre (i + 0.5, j + 0.5).
    """
    if n == 1:
        return (i + 0.5)[None, :], (j + 0.5)[None, :]
    xs, ys = [], []
    for cell in range(n * n):
        a, b = divmod(cell, n)
        xs.append(i + (b + hash_pixel(i, j, cell, 0)) / n)
        ys.append(j + (a + hash_pixel(i, j, cell, 1)) / n)
    return np.array(xs), np.array(ys)
