"""The compiled engine: the Whitted integrator one ray at a time, in machine code (numba, extra `fast`).

numpy's throughput on arrays bounds the wavefront engine (rtcli/wavefront/) at
about 1.4 ns per element-operation, with dozens of operations per ray and bounce.
This package runs the same integrator one ray at a time, compiled, on the same
kernels (rtcli/kernels/variants.py), and gives the same pixels (tests/compiled/test_compiled.py
renders every supported scene both ways). Which engine renders a job is decided in one
place, rtcli/rendering/engine.py, from what this package says: what it cannot render
(pack.unsupported), why it cannot start (why_not), whether it starts at once or its code is
cached (starts_at_once, ready_to_load). It also gives the numpy engine its compiled BVH
walks (walks.py) and tree build (build.py), through that place.

The integrator starts from its machine code file (rtcli/kernels/machinecode) when there is
one for this process, at once and without numba. Otherwise numba is imported,
and the integrator compiled or loaded from numba's on-disk cache, only when a render
takes this path; that writes the machine code file after a compile (and `rtcli warmup`
writes it). numba's cache notices when a function's own file changes, not when a
function it calls (in another file) does, so `drop_stale_cache` empties it, and the
machine code files, whenever any source the engine is made of changes.

Loading numba and its cached code takes about 0.5 s, more than the numpy engine needs
for a small image; with the machine code file it starts at once.
"""

from __future__ import annotations

import copy
import os
import time
from pathlib import Path

import numpy as np

from rtcli.compiled.build import runner
from rtcli.compiled.loading import Load, cached, ready, say
from rtcli.compiled.pack import frames, geometry, lanes, looks, unsupported
from rtcli.core.camera import Camera
from rtcli.errors import RtcliError
from rtcli.kernels import machinecode, numba_cache, variants
from rtcli.stats import Stats

__all__ = ["Compiled", "Load", "ready_to_load", "starts_at_once", "unsupported", "why_not"]


class Compiled:
    """A scene packed for the compiled integrator; trace_pixels() stands in for camera rays + trace.

    Making one loads the integrator's machine code at once, from its machine code file
    (rtcli/kernels/machinecode) or through numba (from numba's cache, or compiling it):
    worker processes forked afterwards inherit it."""

    def __init__(self, scene, bvh: bool = True, notes=None, start: float | None = None):
        start = time.perf_counter() if start is None else start
        self.geometry, stack = geometry(scene, tree=bvh and scene.wants_bvh, levels=runner())
        self.looks, self.stack = looks(scene), np.empty(2 * stack, dtype=np.int64)   # a packet's entry: 2 words
        self.frames, self.lanes = frames(self.looks.max_depth), lanes()
        nowhere, none = Camera(*np.zeros((4, 3))), np.zeros(0)
        self.empty_call = args = self._args(nowhere.row, none, none, 1, 1, np.zeros(4, dtype=np.int64),
                                            np.empty((0, 3)))       # no ray: the arguments' layout
        self.entry = machinecode.load(ENTRY)
        if self.entry is not None and self.entry.fits(args):
            self.load = Load(time.perf_counter() - start)
            return
        self.entry, why = None, _import_integrator()
        if why:
            raise RtcliError(why)
        self.load = ready([compiled_integrator()], lambda: compiled_integrator()(*args), "the render engine",
                          "about half a minute", notes, start)     # no ray: just the machine code
        if self.load.compile_seconds:                   # so that later processes start without numba
            began = time.perf_counter()
            why = machinecode.make(ENTRY, compiled_integrator(), args)
            spent = time.perf_counter() - began
            self.load += Load(spent, spent)
            (notes or say)(f"machine code file written in {spent:.1f} s: later renders start without numba" if
                           why is None else f"no machine code file ({why}): later renders load numba")

    def twin(self) -> Compiled:
        """The same engine with scratch of its own (the integrator's stack and frames), for another
        thread; the packed scene is shared, and only read. The machine code file's entry lets go of
        Python's lock while it traces (ctypes), so twins trace at once (rtcli/preview/passes.py)."""
        other = copy.copy(self)
        other.stack, other.frames, other.lanes = (np.empty_like(a) for a in (self.stack, self.frames, self.lanes))
        return other

    def _args(self, cam_row, x, y, nc, nr, counts, out) -> tuple:
        return self.geometry, self.looks, cam_row, x, y, nc, nr, counts, self.stack, out, self.frames, self.lanes

    def trace_pixels(self, cam, x: np.ndarray, y: np.ndarray, nc: int, nr: int, stats: Stats) -> np.ndarray:
        """Colors (n, 3) of the camera's rays through pixel coordinates (x, y)."""
        counts = np.zeros(4, dtype=np.int64)
        x, y = (np.ascontiguousarray(v, dtype=float) for v in (x, y))
        colors = np.empty((len(x), 3))
        (self.entry or compiled_integrator())(*self._args(cam.row, x, y, nc, nr, counts, colors))
        stats.add(Stats(*(int(c) for c in counts)))
        return colors


ENTRY = "trace_camera"


def compiled_integrator():
    # start-up: the integrator's module compiles its dispatch with numba when imported, which a
    # render from the machine code files never loads
    from rtcli.compiled.tracing import trace_camera
    return variants.compiled(trace_camera)


PACKAGE = Path(numba_cache.PACKAGE_DIR)
STAMP = "rtcli-compiled.sha256"
CACHED = ("*.nbi", "*.nbc", "rtcli-*.so", "rtcli-*.json")     # numba's files and the machine code files


def cache_places() -> list[tuple[list[Path], bool]]:
    """Every place numba may keep rtcli's machine code, as (its folders, the compiled one first;
    whether rtcli uses it now): beside the sources, RTCLI_CACHE_DIR, NUMBA_CACHE_DIR, rtcli's per-user
    cache, and numba's own per-user cache (where numba puts it for a read-only install by itself)."""
    dirs = [PACKAGE / "compiled"] + [PACKAGE / d for d in numba_cache.COMPILED_DIRS if d != "compiled"]
    where = numba_cache.cache_location()
    places = [([d / "__pycache__" for d in dirs], where.enabled and where.root is None)]
    roots = [os.environ.get(numba_cache.CACHE_ENV), os.environ.get("NUMBA_CACHE_DIR"), numba_cache.user_cache_dir(),
             _numba_user_cache()]
    for root in dict.fromkeys(os.path.abspath(os.path.expanduser(r)) for r in roots if r):
        folders = [Path(root) / numba_cache.numba_subfolder(str(d)) for d in dirs]
        places.append((folders, where.enabled and where.root == root))
    return places


def _numba_user_cache() -> str:
    """numba's own per-user cache folder (its appdirs' user_cache_dir for "numba")."""
    if os.name == "nt":
        return os.path.join(numba_cache.user_cache_base(), "numba", "Cache")
    return os.path.join(numba_cache.user_cache_base(), "numba")


def drop_stale_cache() -> None:
    """Delete numba's cached machine code of rtcli, wherever it may be (cache_places), when rtcli's
    sources differ from the ones it was compiled from (a fingerprint kept beside it,
    rtcli-compiled.sha256 in the compiled folder's cache). numba's own check only looks at the
    file of the function it loads, not at the files of the kernels compiled into it."""
    digest = machinecode.sources_digest(PACKAGE)
    for folders, used in cache_places():
        stamp = folders[0] / STAMP
        try:
            if stamp.exists() and stamp.read_text() == digest:
                continue
            found = [f for folder in folders if folder.is_dir() for pattern in CACHED for f in folder.glob(pattern)]
            for f in found:
                f.unlink()
            if used or found:
                stamp.parent.mkdir(parents=True, exist_ok=True)
                stamp.write_text(digest)
        except OSError:                # not writable: numba cannot use it either
            pass


_cache_checked = False


def why_not() -> str | None:
    """Make the compiled integrator ready to load: its machine code file (rtcli/kernels/machinecode)
    when there is one for this process, else numba and the integrator imported; why not, if it
    cannot be. The cache is checked against the sources once a process (a batch, a watch or a
    cluster worker renders many jobs)."""
    global _cache_checked
    if not variants.ENABLED:
        return "numba is not installed (pip install -e '.[fast]' from rtcli's folder)"
    if not _cache_checked:
        drop_stale_cache()
        _cache_checked = True
    if machinecode.load(ENTRY) is not None:
        return None                 # numba is imported only if a scene's arguments do not fit the file
    return _import_integrator()


def _import_integrator() -> str | None:
    """Import numba and the compiled integrator; why not, if they cannot be."""
    try:
        import rtcli.compiled.integrator  # noqa: F401
    except ImportError as e:
        return f"numba cannot be loaded ({e})"
    return None


def ready_to_load() -> bool:
    """Whether the compiled integrator's machine code is at hand (its file, numba's cache, or in
    memory), so that starting the engine loads it rather than compiling for a minute: a forecast
    (loading.cached)."""
    if starts_at_once():
        return True
    if why_not() is not None:
        return False
    entry = compiled_integrator()
    return bool(entry.signatures) or cached(entry) is True


def starts_at_once() -> bool:
    """Whether the compiled integrator would start from its machine code file, without numba."""
    return why_not() is None and machinecode.load(ENTRY) is not None
