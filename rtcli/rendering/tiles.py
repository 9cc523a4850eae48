"""From a scene to a float image: the pixel loop of notes 000 11.7 and 002, in tiles.

The image is cut into tiles, each traced as one wavefront of rays, so memory is
bounded by the tile size whatever the image size. Tiles go to worker processes;
every pixel's value depends only on the pixel (jitter is hashed from its
coordinates), so the image is the same for any tile size and worker count.
With `block_size` B, one ray goes through the top-left pixel of each B x B block
and the whole block gets its color (002's raytrace loop). Job.engine asks for the
numpy engine (rtcli/wavefront/) or the compiled one (rtcli/compiled/); engine.py decides.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass

import numpy as np

from rtcli.core.display import to_8bit, to_8bit_alpha
from rtcli.core.jitter import sample_positions
from rtcli.core.objects import object_ids
from rtcli.core.scene import Scene
from rtcli.rendering import engine as engines
from rtcli.rendering.pool import held_signals, interrupted_once, stop_pool, watch_worker, worker_died
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.rays import camera_rays
from rtcli.wavefront.trace import trace

TILE = 128                                 # tile edge in pixels (rays per tile: TILE^2 x samples^2)


@dataclass(frozen=True)
class Job:
    """What to render: the output size, the preview block and the tile edge."""

    width: int
    height: int
    block_size: int = 1
    tile: int = TILE
    signature: bool = False          # trace primary rays only and return object ids
    gamma: bool = False              # sRGB-encode when converting to 8 bits
    engine: str = "auto"             # auto, numpy or compiled (rtcli/rendering/engine.py)
    bvh: bool = True                 # a BVH over the scene's objects when there are enough (Scene.wants_bvh)
    linear: bool = False             # keep the traced colors (float64, unclamped) instead of 8 bits
    alpha: bool = False              # a fourth channel: the share of each pixel's samples that hit an object


def render_tile(scene: Scene, job: Job, i: np.ndarray, j: np.ndarray,
                engine=None) -> tuple[np.ndarray, Stats]:
    """Colors (or ids) of the pixels (i, j) of the full-size image; a compiled `engine` traces
    them instead of the numpy engine when given. The kernels make inf and NaN on purpose (a
    ray parallel to a plane, a miss), so numpy's warnings about them are off."""
    stats = Stats()
    cam = scene.camera(job.width, job.height)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if job.signature:
            rays = camera_rays(cam, i + 0.5, j + 0.5, job.width, job.height)
            hits = find_first_hit(scene, rays)
            stats.primary += len(rays)
            ids = object_ids(scene.objects)
            return ids[hits.obj], stats
        xs, ys = sample_positions(i, j, scene.settings.samples)
        stats.primary += xs.size
        if engine:
            colors = engine.trace_pixels(cam, xs.ravel(), ys.ravel(), job.width, job.height, stats)
        else:
            colors = trace(scene, camera_rays(cam, xs.ravel(), ys.ravel(), job.width, job.height), 1, stats).T
    colors = colors.reshape(len(xs), len(i), 3)
    if job.alpha:
        return with_alpha(scene, cam, job, xs, ys, colors), stats
    return colors.mean(axis=0), stats


def with_alpha(scene: Scene, cam, job: Job, xs: np.ndarray, ys: np.ndarray, colors: np.ndarray) -> np.ndarray:
    """(n, 4): the straight color of each pixel (the mean of its samples that hit an object, 0 when
    none does) and its alpha (the share of its samples that hit one). The primary rays are traced
    again by the numpy engine for their hits, whichever engine traced the colors (the same hits,
    bit for bit). A pixel whose samples all hit has the color it has without alpha, to the bit."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        hits = find_first_hit(scene, camera_rays(cam, xs.ravel(), ys.ravel(), job.width, job.height))
    hit = np.isfinite(hits.t).reshape(colors.shape[:2])
    count = hit.sum(axis=0)
    straight = np.where(hit[..., None], colors, 0.0).sum(axis=0) / np.maximum(count, 1)[:, None]
    return np.concatenate([straight, (count / hit.shape[0])[:, None]], axis=1)


def _tiles(job: Job, samples: int = 1):
    """(rows, cols) index ranges of the traced grid: every pixel, or each block's top-left.

    With n x n samples per pixel the tile edge shrinks n-fold, so a tile is always
    about tile^2 rays: memory does not grow with the sample count.
    """
    b, edge = job.block_size, max(1, job.tile // samples)
    rows, cols = np.arange(0, job.height, b), np.arange(0, job.width, b)
    for r in range(0, len(rows), edge):
        for c in range(0, len(cols), edge):
            yield rows[r:r + edge], cols[c:c + edge]


def _run_tile(scene: Scene, engine, job: Job, rows: np.ndarray, cols: np.ndarray):
    """A tile's 8-bit pixels (or ids), small enough to pile up while the parent catches up."""
    jj, ii = np.meshgrid(rows, cols, indexing="ij")
    values, stats = render_tile(scene, job, ii.ravel(), jj.ravel(), engine)
    if not (job.signature or job.linear):
        values = to_8bit_alpha(values, job.gamma) if job.alpha else to_8bit(values, job.gamma)
    return rows, cols, values.reshape(len(rows), len(cols), *values.shape[1:]), stats


_worker_scene = (None, None)               # the scene and its compiled form, sent once to each worker


def _init_worker(scene: Scene, engine) -> None:
    global _worker_scene
    _worker_scene = (scene, engine)
    watch_worker()


def _worker_tile(job: Job, rows, cols):
    return _run_tile(*_worker_scene, job, rows, cols)


def render(scene: Scene, job: Job, workers: int = 1, progress=None, notes=None) -> tuple[np.ndarray, Stats]:
    """The 8-bit image (H, W, 3), or the id map (H, W) uint16 for a signature, or with
    job.linear the float64 colors (H, W, 3).

    Each tile is converted to 8 bits where it is traced, so no float copy of the
    whole image ever exists unless job.linear asks for one. The stats hold apart how long the
    compiled code took to load or compile (load_seconds, compile_seconds); `notes` is told when
    it compiles (default: stderr).
    """
    tiles, traced = plan(scene, job)
    stats, (engine, load) = Stats(), engines.prepare(scene, job, traced, notes)
    stats.engine = "compiled" if engine else "numpy"            # add() keeps it
    if load:
        stats.load_seconds, stats.compile_seconds = load.seconds, load.compile_seconds
    with contextlib.closing(_map_tiles(scene, engine, job, tiles, workers)) as results:     # stops the pool
        return assemble(job, len(tiles), results, stats, progress), stats


def assemble(job: Job, count: int, results, stats: Stats, progress=None) -> np.ndarray:
    """The image of `count` tiles' results (rows, cols, values, stats) as they come, their counts
    added to `stats` (and its engine taken from them when not set); progress(done, count) after
    each."""
    image = blank(job)
    for done, (rows, cols, values, s) in enumerate(results, 1):
        place(image, job, rows, cols, values)
        stats.add(s)
        stats.engine = stats.engine or s.engine
        if progress:
            progress(done, count)
    return image


def blank(job: Job) -> np.ndarray:
    """The job's image before any tile is placed: 8-bit RGB (RGBA with job.alpha), 16-bit ids for a
    signature, or float64 colors with job.linear."""
    shape = (job.height, job.width) + (() if job.signature else (4,) if job.alpha else (3,))
    return np.zeros(shape, dtype=np.uint16 if job.signature else np.float64 if job.linear else np.uint8)


def plan(scene: Scene, job: Job) -> tuple[list, int]:
    """(tiles, primary rays the whole job traces): the tiles' (rows, cols) index ranges."""
    tiles = list(_tiles(job, 1 if job.signature else scene.settings.samples))
    return tiles, sum(len(r) * len(c) for r, c in tiles) * scene.settings.samples ** 2


def run_tiles(scene: Scene, engine, job: Job, tiles: list) -> list:
    """The tiles traced one after another here: (rows, cols, values, stats) each."""
    return [_run_tile(scene, engine, job, rows, cols) for rows, cols in tiles]


def place(image: np.ndarray, job: Job, rows: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
    """Put a tile's values into the image, each traced pixel over its preview block."""
    b = job.block_size
    block = np.repeat(np.repeat(values, b, axis=0), b, axis=1)
    image[rows[0]:rows[-1] + b, cols[0]:cols[-1] + b] = block[:job.height - rows[0], :job.width - cols[0]]


def _map_tiles(scene: Scene, engine, job: Job, tiles: list, workers: int):
    if workers <= 1 or len(tiles) == 1:
        for rows, cols in tiles:
            yield _run_tile(scene, engine, job, rows, cols)
        return
    context = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker, initargs=(scene, engine))
    finished = False
    with interrupted_once():                    # a second signal would break the unwinding of the first
        try:
            with held_signals():                # an interrupt inside submit() could hang the exit
                futures = [pool.submit(_worker_tile, job, rows, cols) for rows, cols in tiles]
            for f in as_completed(futures):
                yield f.result()
            finished = True
        except BrokenProcessPool:
            raise worker_died(pool) from None
        finally:
            stop_pool(pool, finished)
