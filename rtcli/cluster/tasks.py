"""The workers' side of a render on a cluster: a group of tiles or a whole frame, traced where the
task runs, from the scene built out of the bundle's bytes. A worker keeps the scenes it built for
its last tasks (and an animation's parsed scene), so the tiles of a still or the frames of an
animation reuse the scene, its meshes and the engine."""

from __future__ import annotations

import threading
from collections import OrderedDict

from rtcli.cluster.notes import told
from rtcli.cluster.software import fingerprint, mismatch
from rtcli.errors import RtcliError
from rtcli.rendering import engine as engines
from rtcli.rendering import tiles as rendering
from rtcli.rendering.frames import apply
from rtcli.scenefile import yamlfile
from rtcli.scenefile.animation import Animation
from rtcli.scenefile.files import serving

KEPT_SCENES = 2                   # built scenes a worker keeps (an animation's frames come one by one)


def blob(data: bytes) -> bytes:
    """A file's bytes, as the task that holds them on the cluster."""
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
    files = {path: (real, blobs[digest]) for path, real, digest in spec["manifest"]}
    with serving(files):
        animation = _kept(_animations, spec["key"], lambda: Animation(yamlfile.load(spec["scene_path"])), 2)
        scene = animation.scene(frame)
    return apply(scene, spec["overrides"])


def _checked(spec: dict) -> None:
    """Refuse to work for a client whose software differs from this worker's."""
    if (refusal := mismatch(spec["fingerprint"], fingerprint(), _worker_address())) is not None:
        raise refusal


def _worker_address() -> str:
    try:
        from distributed import get_worker  # the cluster extra: only on a worker
        return get_worker().address
    except (ImportError, ValueError):
        return "(unknown)"


def tiles_task(spec: dict, blobs: dict, frame: int, job, traced: int, tiles: list) -> list:
    """Trace a group of tiles of `frame`: [(rows, cols, values, stats)], as rtcli.rendering.tiles.run_tiles."""
    try:
        _checked(spec)
        with _lock:
            key = (spec["key"], frame, tuple(sorted(spec["overrides"].items())), job, traced)
            scene, engine = _kept(_scenes, key, lambda: _prepared(spec, blobs, frame, job, traced), KEPT_SCENES)
        results = rendering.run_tiles(scene, engine, job, tiles)
        for *_, stats in results:
            stats.engine = "compiled" if engine else "numpy"
        return results
    except RtcliError as e:
        raise RtcliError(str(e)) from None


def _prepared(spec, blobs, frame, job, traced):
    """(scene, engine) of `frame`; the engine's notes, and its compile time, told to the client."""
    scene, notes = _scene(spec, blobs, frame), told()
    engine, load = engines.prepare(scene, job, traced, notes)
    if notes and load:
        notes.compiled(load.compile_seconds)
    return scene, engine


def frame_task(spec: dict, blobs: dict, frame: int, job):
    """Render a whole frame here, one tile after another: (frame, image, stats)."""
    try:
        _checked(spec)
        with _lock:
            scene = _scene(spec, blobs, frame)
        notes = told()
        image, stats = rendering.render(scene, job, 1, notes=notes)
        if notes:
            notes.compiled(stats.compile_seconds)
        return frame, image, stats
    except RtcliError as e:
        raise RtcliError(str(e)) from None
