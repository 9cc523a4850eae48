"""The compiled engine: the Whitted integrator per ray in machine code (numba, extra `fast`).

numpy's throughput on (n, 3) arrays bounds the wavefront core (trace.py) at
about 1.4 ns per element-operation, with dozens of operations per ray and bounce.
This package runs the same integrator one ray at a time, compiled, and gives
the same pixels (tests/test_fast.py renders every supported scene both ways).
`--engine auto` (the default) takes it when numba is installed and the scene
holds only what it supports (pack.unsupported), else the numpy core.

numba is imported, and the integrator compiled or loaded from numba's on-disk
cache, only when a render takes this path. numba's cache notices when a
function's own file changes, not when a function it calls (in another file) does,
so `_drop_stale_cache` empties it whenever any of the compiled sources change.

Loading numba and the cached code takes about 0.8 s, more than the numpy core
needs for a small image, so `auto` takes the compiled engine only from
AUTO_RAYS primary rays up (a 1280x800 image, or 640x480 with --samples 2).
"""

from __future__ import annotations

import contextlib
import hashlib
import sys
from pathlib import Path

import numpy as np

from rtcli import kernels
from rtcli.compiled.pack import geometry, looks, unsupported
from rtcli.core.camera import Camera
from rtcli.errors import RtcliError
from rtcli.stats import Stats


class Compiled:
    """A scene packed for the compiled integrator; trace_pixels() stands in for camera rays + trace.trace.

    Making one compiles the integrator, or loads it from numba's cache, at once: worker
    processes forked afterwards inherit the machine code."""

    def __init__(self, scene):
        self.geometry, stack = geometry(scene)
        self.looks, self.stack = looks(scene), np.empty(stack, dtype=np.int64)
        nowhere, none = Camera(*np.zeros((4, 3))), np.zeros(0)
        with _no_blas_lookup():
            self.trace_pixels(nowhere, none, none, 1, 1, Stats())        # no ray: just the machine code

    def trace_pixels(self, cam, x: np.ndarray, y: np.ndarray, nc: int, nr: int, stats: Stats) -> np.ndarray:
        """Colors of the camera's rays through pixel coordinates (x, y): trace(cam.rays(x, y, nc, nr))
        without building the rays in numpy."""
        from rtcli.compiled.integrator import trace_camera
        counts = np.zeros(4, dtype=np.int64)
        x, y = (np.ascontiguousarray(v, dtype=float) for v in (x, y))
        colors = trace_camera(self.geometry, self.looks, *(np.asarray(v, dtype=float) for v in
                              (cam.eye, cam.origin, cam.right, cam.down)), x, y, nc, nr, counts, self.stack)
        stats.add(Stats(*(int(c) for c in counts)))
        return colors


@contextlib.contextmanager
def _no_blas_lookup():
    """numba imports scipy.linalg when it starts, ~0.2 s, to find a BLAS for np.dot in compiled code;
    the integrator needs none, so the module numba looks for is hidden meanwhile."""
    name = "scipy.linalg.cython_blas"
    if name in sys.modules:
        yield
        return
    sys.modules[name] = None                         # import fails at once: numba goes on without BLAS
    try:
        yield
    finally:
        if sys.modules.get(name, 0) is None:
            del sys.modules[name]


SOURCES = ("pack.py", "shapes.py", "query.py", "uv.py", "integrator.py")     # what the machine code is made of


def _drop_stale_cache() -> None:
    """Delete numba's cached machine code of this package when its sources differ from the
    ones it was compiled from (a fingerprint kept beside it)."""
    here = Path(__file__).parent
    cache, digest = here / "__pycache__", hashlib.sha256()
    for name in SOURCES:
        digest.update((here / name).read_bytes())
    stamp = cache / "rtcli-fast.sha256"
    try:
        if stamp.exists() and stamp.read_text() == digest.hexdigest():
            return
        for f in cache.glob("*.nb[ic]"):
            f.unlink()
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest.hexdigest())
    except OSError:                    # a read-only install: numba keeps its cache elsewhere
        pass


def _load() -> str | None:
    """Import the compiled integrator (numba); why not, if it cannot be."""
    if not kernels.ENABLED:
        return "numba is not installed (pip install 'rtcli[fast]')"
    _drop_stale_cache()
    try:
        import rtcli.compiled.integrator  # noqa: F401
    except ImportError as e:
        return f"numba cannot be loaded ({e})"
    return None


AUTO_RAYS = 1_000_000


def choose(scene, engine: str, rays: int = AUTO_RAYS) -> Compiled | None:
    """The compiled engine for `scene`, or None for the numpy core; RtcliError when
    `engine` is "compiled" and it cannot be had. `rays`: how many primary rays the job traces."""
    if engine == "numpy" or (engine == "auto" and rays < AUTO_RAYS):
        return None
    shape = unsupported(scene)
    why = f"it does not handle {shape} (--engine numpy does)" if shape else _load()
    if why is None:
        return Compiled(scene)
    if engine == "compiled":
        raise RtcliError(f"--engine compiled cannot render this scene: {why}")
    return None
