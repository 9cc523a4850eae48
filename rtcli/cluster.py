"""Renders spread over a Dask cluster (README.md, "Clusters"); needs the extra `cluster`.

A still goes out as groups of tiles, about RAYS_PER_TASK primary rays each and at
least TASKS_PER_WORKER per worker, so that Dask's few milliseconds a task stay small
and every worker has work until the end; an animation goes out a frame a task. Every
pixel depends only on the scene and the pixel (jitter is hashed from the pixel's
coordinates, rtcli/rendering/tiles.py), so the images are byte for byte the ones a local render
makes, whatever the cluster's size, the grouping, or a worker that dies and whose
tasks run again elsewhere.

The scene reaches the workers as the bytes of the files the client read (the YAML,
its includes, meshes and textures), each file a task keyed by the SHA-256 of its
content: sent to the scheduler once, computed on one worker and copied between
workers as needed, and computed again if every copy is lost with its worker. A worker
builds the scene from those bytes (rtcli.scenefile.files.serving) and keeps the
built scenes of its last tasks, so the tiles of a still or the frames of an
animation reuse the parsed scene, its meshes and the engine.

Workers must run the same rtcli and libraries as the client, or pixels could differ:
the client compares every worker's `fingerprint()` with its own when it connects,
and every task compares it again where it runs (for workers that join later).

A worker that compiles the engine says so to the client while it does, and the client
says after the render which workers compiled and for how long (rtcli/cluster_engine.py).

distributed is imported only here, and this module only when a cluster option is
given.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import re
import signal
import sys
import threading
import warnings
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

from rtcli import __version__
from rtcli.cluster_engine import TOPIC, Heard, told
from rtcli.errors import RtcliError, plural, shown

RAYS_PER_TASK = 2_000_000         # primary rays a task traces, at most (unless that leaves workers idle)
TASKS_PER_WORKER = 4              # at least this many tasks a worker thread, so all finish together
KEPT_SCENES = 2                   # built scenes a worker keeps (an animation's frames come one by one)
INSTALL = "pip install -e '.[cluster]' in the rtcli folder (rtcli is not on the package index)"
LIBRARIES = ("numpy", "numba", "llvmlite", "PIL", "yaml")


# --- where the cluster is ---
@dataclass(frozen=True)
class Target:
    """The cluster: a scheduler's address, a scheduler file, or a LocalCluster of `local` workers."""

    address: str | None = None
    file: str | None = None
    local: int = 0

    def __str__(self) -> str:
        if self.local:
            return f"a local cluster of {plural(self.local, 'worker')}"
        return f"the Dask scheduler at {shown(self.address)}"


def target(address: str | None, file: str | None, local: int | None) -> Target | None:
    """The Target the options name (at most one of them), or None."""
    given = [name for name, value in (("--cluster", address), ("--cluster-file", file),
                                      ("--local-cluster", local)) if value]
    if len(given) > 1:
        raise RtcliError(f"{' and '.join(given)}: give one way to reach a cluster")
    if not given:
        return None
    if file:
        address = _scheduler_address(file)
    if address:
        address = _checked_address(address, f"--cluster-file {shown(file)}: its address" if file else "--cluster")
    return Target(address, file, local or 0)


def _checked_address(address: str, what: str) -> str:
    """A scheduler's address as Dask takes it, tcp:// added when no scheme is given."""
    full = address if "://" in address else f"tcp://{address}"
    if not re.fullmatch(r"(tcp|tls|ws|wss)://(\[[0-9a-fA-F:.]+\]|[^\s/:\[\]]+):\d{1,5}", full):
        raise RtcliError(f"{what} {shown(address)}: give the scheduler's address as tcp://HOST:PORT")
    return full


def _scheduler_address(path: str) -> str:
    """The address in a scheduler file (`dask scheduler --scheduler-file PATH` writes it)."""
    try:
        with open(path, encoding="utf-8") as f:
            address = json.load(f).get("address")
    except FileNotFoundError:
        raise RtcliError(f"--cluster-file {shown(path)}: file not found") from None
    except (OSError, ValueError, AttributeError) as e:
        raise RtcliError(f"--cluster-file {shown(path)}: not a Dask scheduler file ({e})") from None
    if not isinstance(address, str) or not address:
        raise RtcliError(f"--cluster-file {shown(path)}: names no scheduler address")
    return address


def _distributed():
    try:
        import distributed
    except ImportError:
        raise RtcliError(f"a cluster needs Dask's distributed scheduler, which is not installed: {INSTALL}") \
            from None
    return distributed


# --- the same software everywhere ---
_fingerprint: dict | None = None


def fingerprint() -> dict:
    """What the pixels depend on besides the scene: rtcli's version and sources, Python's and the
    libraries' versions (numba's too: it decides the engine)."""
    global _fingerprint
    if _fingerprint is None:
        package = Path(__file__).resolve().parent
        digest = hashlib.sha256()
        for f in sorted(package.rglob("*.py")):
            digest.update(str(f.relative_to(package)).encode() + b"\0" + f.read_bytes())
        found = {"rtcli": f"{__version__} (sources {digest.hexdigest()[:12]})",
                 "python": ".".join(map(str, sys.version_info[:3]))}
        for name in LIBRARIES:
            try:
                found[name] = __import__(name).__version__
            except ImportError:
                found[name] = "not installed"
        _fingerprint = found
    return _fingerprint


def mismatch(client: dict, worker: dict, where: str) -> RtcliError | None:
    """The refusal when a worker's fingerprint differs from the client's, or None."""
    differ = [f"{name} {client.get(name)} here, {worker.get(name)} there"
              for name in sorted(set(client) | set(worker)) if client.get(name) != worker.get(name)]
    if not differ:
        return None
    return RtcliError(f"the worker {where} runs other software ({'; '.join(differ)}): its pixels could differ; "
                      "install the same rtcli and libraries on every worker")


# --- the scene as files ---
@dataclass(frozen=True)
class Bundle:
    """The files a scene was built from: (path as the loader named it, real path, SHA-256) each,
    and their bytes by digest."""

    scene_path: str
    manifest: tuple
    blobs: dict

    @staticmethod
    def of(scene_path: str, kept: dict) -> Bundle:
        """From the files rtcli.scenefile.files.collecting kept while the client loaded the scene."""
        manifest, blobs = [], {}
        for path, (real, data) in sorted(kept.items()):
            digest = hashlib.sha256(data).hexdigest()
            manifest.append((path, real, digest))
            blobs[digest] = data
        return Bundle(scene_path, tuple(manifest), blobs)

    @property
    def key(self) -> str:
        return hashlib.sha256(json.dumps([self.scene_path, self.manifest]).encode()).hexdigest()

    @property
    def size(self) -> int:
        return sum(len(b) for b in self.blobs.values())


def _blob(data: bytes) -> bytes:
    return data


# --- on a worker ---
_lock = threading.Lock()
_animations: OrderedDict = OrderedDict()          # bundle key -> Animation (the parsed scene, shared parts)
_scenes: OrderedDict = OrderedDict()              # (bundle key, frame, overrides, job, rays) -> (scene, engine)


def _kept(cache: OrderedDict, key, make, size: int):
    if key in cache:
        cache.move_to_end(key)
        return cache[key]
    value = cache[key] = make()
    while len(cache) > size:
        cache.popitem(last=False)
    return value


def _scene(spec: dict, blobs: dict, frame: int):
    """The scene of `frame`, built here from the bundle's bytes, with the command line's overrides."""
    from rtcli.scenefile import yamlfile
    from rtcli.scenefile.animation import Animation
    from rtcli.scenefile.files import serving
    files = {path: (real, blobs[digest]) for path, real, digest in spec["manifest"]}
    with serving(files):
        animation = _kept(_animations, spec["key"], lambda: Animation(yamlfile.load(spec["scene_path"])), 2)
        scene = animation.scene(frame)
    from rtcli.rendering.frames import apply
    return apply(scene, spec["overrides"])


def _checked(spec: dict) -> None:
    """Refuse to work for a client whose software differs from this worker's."""
    if (refusal := mismatch(spec["fingerprint"], fingerprint(), _worker_address())) is not None:
        raise refusal


def _worker_address() -> str:
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return "(unknown)"


def tiles_task(spec: dict, blobs: dict, frame: int, job, traced: int, tiles: list) -> list:
    """Trace a group of tiles of `frame`: [(rows, cols, values, stats)], as rtcli.rendering.tiles.run_tiles."""
    from rtcli.rendering.tiles import run_tiles
    try:
        _checked(spec)
        with _lock:
            key = (spec["key"], frame, tuple(sorted(spec["overrides"].items())), job, traced)
            scene, engine = _kept(_scenes, key, lambda: _prepared(spec, blobs, frame, job, traced), KEPT_SCENES)
        results = run_tiles(scene, engine, job, tiles)
        for *_, stats in results:
            stats.engine = "compiled" if engine else "numpy"
        return results
    except RtcliError as e:
        raise RtcliError(str(e)) from None


def _prepared(spec, blobs, frame, job, traced):
    """(scene, engine) of `frame`; the engine's notes, and its compile time, told to the client."""
    from rtcli.rendering.tiles import prepare
    scene, notes = _scene(spec, blobs, frame), told()
    engine, load = prepare(scene, job, traced, notes)
    if notes and load:
        notes.compiled(load.compile_seconds)
    return scene, engine


def frame_task(spec: dict, blobs: dict, frame: int, job):
    """Render a whole frame here, one tile after another: (frame, image, stats)."""
    from rtcli.rendering.tiles import render
    try:
        _checked(spec)
        with _lock:
            scene = _scene(spec, blobs, frame)
        notes = told()
        image, stats = render(scene, job, 1, notes=notes)
        if notes:
            notes.compiled(stats.compile_seconds)
        return frame, image, stats
    except RtcliError as e:
        raise RtcliError(str(e)) from None


# --- on the client ---
def groups(tiles: list, samples: int, threads: int) -> list[list]:
    """Consecutive tiles in groups of about RAYS_PER_TASK primary rays, at least TASKS_PER_WORKER
    groups per worker thread (as many as there are tiles, at most)."""
    rays = sum(len(r) * len(c) for r, c in tiles) * samples ** 2
    n = min(len(tiles), max(math.ceil(rays / RAYS_PER_TASK), TASKS_PER_WORKER * max(threads, 1)))
    size = len(tiles) / n
    return [tiles[round(k * size):round((k + 1) * size)] for k in range(n)]


class Session:
    """A connection to the cluster for one command: `with Session(target) as s: ...`. `notes` hears
    what the workers say about their engine, as they say it (default: stderr; cluster_engine.Heard)."""

    def __init__(self, where: Target, notes=None):
        from rtcli.compiled.loading import say
        self.where, self.client, self.cluster, self.futures = where, None, None, []
        self.heard = Heard(notes or say)
        self._quiet = contextlib.ExitStack()

    def __enter__(self) -> Session:
        distributed = _distributed()
        self._quiet.enter_context(_quiet())
        try:
            self._connect(distributed)
            self.client.subscribe_topic(TOPIC, self.heard)       # before any task: no note is missed
            self._check_workers()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _connect(self, distributed) -> None:
        if self.where.local:
            with _sigint_ignored():              # the workers leave Ctrl-C to this process, which stops them
                self.cluster = distributed.LocalCluster(
                    n_workers=self.where.local, threads_per_worker=1, processes=True, host="127.0.0.1",
                    dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
            self.client = distributed.Client(self.cluster, set_as_default=False)
            return
        try:
            self.client = distributed.Client(self.where.address, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as e:
            raise RtcliError(f"cannot reach the Dask scheduler at {shown(self.where.address)}: "
                             f"{' '.join(str(e).split())}") from None

    def _check_workers(self) -> None:
        """Refuse workers whose software differs; wait a while for a first worker."""
        distributed = _distributed()
        try:
            self.client.wait_for_workers(1, timeout=connect_timeout())
        except (TimeoutError, distributed.TimeoutError):
            raise RtcliError(f"{self.where} has no workers (start some: README.md, Clusters)") from None
        try:
            found = self.client.run(fingerprint)
        except Exception as e:            # a worker without rtcli, or with one too old to say what it runs
            raise RtcliError(f"the workers of {self.where} cannot run rtcli ({type(e).__name__}: {e}); install "
                             "the same rtcli and libraries on every worker") from None
        for address, theirs in sorted(found.items()):
            if (refusal := mismatch(fingerprint(), theirs, address)) is not None:
                raise refusal

    @property
    def threads(self) -> int:
        return sum(self.client.nthreads().values())

    def __exit__(self, *exc) -> None:
        try:
            if self.client is not None:
                with contextlib.suppress(Exception):
                    self.client.cancel(self.futures)
                with contextlib.suppress(Exception):
                    self.client.close(timeout=5)
            if self.cluster is not None:
                with contextlib.suppress(Exception):
                    self.cluster.close(timeout=5)
        finally:
            self._quiet.close()

    # --- work ---
    def send(self, bundle: Bundle, overrides: dict) -> tuple[dict, dict]:
        """(spec, blobs): what every task needs to build the scene; each file a task of its own,
        keyed by its content."""
        blobs = {digest: self.client.submit(_blob, data, key=f"rtcli-file-{digest}", pure=False)
                 for digest, data in bundle.blobs.items()}
        spec = {"key": bundle.key, "scene_path": bundle.scene_path, "manifest": bundle.manifest,
                "overrides": overrides, "fingerprint": fingerprint()}
        return spec, blobs

    def tiles(self, bundle: Bundle, overrides: dict, frame: int, job, traced: int, tiles: list, samples: int):
        """The results of every tile, group by group as they finish."""
        spec, blobs = self.send(bundle, overrides)
        self.futures = [self.client.submit(tiles_task, spec, blobs, frame, job, traced, group, pure=False)
                        for group in groups(tiles, samples, self.threads)]
        for results in self._finished():
            yield from results

    def frames(self, bundle: Bundle, overrides: dict, frames: list[int], job):
        """(frame, image, stats) of each frame, as they finish."""
        spec, blobs = self.send(bundle, overrides)
        self.futures = [self.client.submit(frame_task, spec, blobs, k, job, pure=False, priority=-k)
                        for k in frames]
        yield from self._finished()

    def run(self, function, *args) -> dict:
        """`function(*args)` on every worker at once (Client.run): {worker address: its result, or the
        exception it raised}."""
        distributed = _distributed()
        try:
            return self.client.run(function, *args, on_error="return")
        except (distributed.CancelledError, OSError) as e:
            raise RtcliError(f"lost {self.where} ({type(e).__name__})") from None

    def _finished(self):
        """The futures' results as they finish; then which workers compiled the engine meanwhile."""
        distributed = _distributed()
        try:
            for future in distributed.as_completed(self.futures, loop=self.client.loop):
                yield future.result()
                future.release()
            self.heard.summary()
        except distributed.KilledWorker as e:
            raise RtcliError(f"a task of this render kept killing its workers (out of memory?): {e}") from None
        except (distributed.CancelledError, OSError) as e:
            raise RtcliError(f"lost {self.where} mid-render ({type(e).__name__}); the render was stopped") \
                from None
        except RtcliError:
            raise
        except Exception as e:           # a failure on a worker: shown in one line
            raise RtcliError(f"a worker failed: {type(e).__name__}: {e}") from None


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored meanwhile, so that processes started inside the block inherit it ignored (Python
    keeps an ignored SIGINT ignored): Ctrl-C at a terminal signals the whole process group."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def connect_timeout() -> float:
    """Dask's connect timeout (distributed.comm.timeouts.connect), in seconds."""
    import dask
    from dask.utils import parse_timedelta
    return parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), "s")


@contextlib.contextmanager
def _quiet():
    """Dask's log lines and warnings (a worker restarted, a large graph) stay off the terminal:
    rtcli speaks in one line."""
    handlers = logging.getLogger("distributed").handlers       # Dask's own, fed by all its loggers
    levels = [h.level for h in handlers]
    for h in handlers:
        h.setLevel(logging.CRITICAL + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            yield
        finally:
            for h, level in zip(handlers, levels):
                h.setLevel(level)

