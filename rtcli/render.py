"""From a scene to a float image: the pixel loop of notes 000 11.7 and 002, in tiles.

The image is cut into tiles, each traced as one wavefront of rays, so memory is
bounded by the tile size whatever the image size. Tiles go to worker processes;
every pixel's value depends only on the pixel (jitter is hashed from its
coordinates), so the image is the same for any tile size and worker count.
With `block_size` B, one ray goes through the top-left pixel of each B x B block
and the whole block gets its color (002's raytrace loop). Job.engine picks the
numpy core or the compiled integrator (rtcli/fast/) to trace the primary rays.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass

import numpy as np

from rtcli import compiled as fast
from rtcli import kernels
from rtcli.core.jitter import uniform
from rtcli.core.scene import Scene
from rtcli.pool import stop_pool, watch_worker, worker_died
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.trace import trace
from rtcli.writer import to_8bit

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
    engine: str = "auto"             # auto, numpy or compiled (see rtcli.compiled.choose)


def sample_positions(i: np.ndarray, j: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n stratified, jittered sample positions per pixel, shape (n*n, len(i)) each.

    With n = 1 the single sample is the pixel centre (i + 0.5, j + 0.5).
    """
    if n == 1:
        return (i + 0.5)[None, :], (j + 0.5)[None, :]
    xs, ys = [], []
    for cell in range(n * n):
        a, b = divmod(cell, n)
        xs.append(i + (b + uniform(i, j, cell, 0)) / n)
        ys.append(j + (a + uniform(i, j, cell, 1)) / n)
    return np.array(xs), np.array(ys)


def render_tile(scene: Scene, job: Job, i: np.ndarray, j: np.ndarray,
                compiled: fast.Compiled | None = None) -> tuple[np.ndarray, Stats]:
    """Colors (or ids) of the pixels (i, j) of the full-size image; `compiled` traces
    them instead of the numpy core when given."""
    stats = Stats()
    cam = scene.camera(job.width, job.height)
    if job.signature:
        rays = cam.rays(i + 0.5, j + 0.5, job.width, job.height)
        hits = find_first_hit(scene, rays)
        stats.primary += len(rays)
        ids = np.array([o.id for o in scene.objects] + [0], dtype=np.uint16)
        return ids[hits.obj], stats
    xs, ys = sample_positions(i, j, scene.settings.samples)
    stats.primary += xs.size
    if compiled:
        colors = compiled.trace_pixels(cam, xs.ravel(), ys.ravel(), job.width, job.height, stats)
    else:
        colors = trace(scene, cam.rays(xs.ravel(), ys.ravel(), job.width, job.height), 1, stats)
    colors = colors.reshape(len(xs), len(i), 3)
    return colors.mean(axis=0), stats


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


def _run_tile(scene: Scene, compiled, job: Job, rows: np.ndarray, cols: np.ndarray):
    """A tile's 8-bit pixels (or ids), small enough to pile up while the parent catches up."""
    jj, ii = np.meshgrid(rows, cols, indexing="ij")
    values, stats = render_tile(scene, job, ii.ravel(), jj.ravel(), compiled)
    if not job.signature:
        values = to_8bit(values, job.gamma)
    return rows, cols, values.reshape(len(rows), len(cols), *values.shape[1:]), stats


_worker_scene = (None, None)               # the scene and its compiled form, sent once to each worker


def _init_worker(scene: Scene, compiled) -> None:
    global _worker_scene
    _worker_scene = (scene, compiled)
    watch_worker()


def _worker_tile(job: Job, rows, cols):
    return _run_tile(*_worker_scene, job, rows, cols)


def render(scene: Scene, job: Job, workers: int = 1, progress=None) -> tuple[np.ndarray, Stats]:
    """The 8-bit image (H, W, 3), or the id map (H, W) uint16 for a signature.

    Each tile is converted to 8 bits where it is traced, so no float copy of the
    whole image ever exists.
    """
    b = job.block_size
    shape = (job.height, job.width) + (() if job.signature else (3,))
    image = np.zeros(shape, dtype=np.uint16 if job.signature else np.uint8)
    stats, tiles = Stats(), list(_tiles(job, 1 if job.signature else scene.settings.samples))
    traced = sum(len(r) * len(c) for r, c in tiles) * scene.settings.samples ** 2
    compiled = None if job.signature else fast.choose(scene, job.engine, traced)
    stats.engine = "compiled" if compiled else "numpy"          # add() keeps it
    with contextlib.closing(_map_tiles(scene, compiled, job, tiles, workers)) as results:   # stops the pool
        for done, (rows, cols, values, s) in enumerate(results, 1):
            block = np.repeat(np.repeat(values, b, axis=0), b, axis=1)
            image[rows[0]:rows[-1] + b, cols[0]:cols[-1] + b] = block[:job.height - rows[0], :job.width - cols[0]]
            stats.add(s)
            if progress:
                progress(done, len(tiles))
    return image, stats


def _uses_kernels(scene: Scene) -> bool:
    """Whether tracing this scene calls the compiled traversal (meshes, sets of spheres)."""
    from rtcli.shapes.mesh import Mesh
    return (any(isinstance(o.shape, Mesh) for o in scene.objects)
            or (scene.accel is not None and scene.accel.all_spheres))


def _map_tiles(scene: Scene, compiled, job: Job, tiles: list, workers: int):
    if workers <= 1 or len(tiles) == 1:
        for rows, cols in tiles:
            yield _run_tile(scene, compiled, job, rows, cols)
        return
    if not compiled and _uses_kernels(scene):
        kernels.warm_up()                  # loaded once here, not once per worker (Compiled loads itself)
    context = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_init_worker, initargs=(scene, compiled))
    finished = False
    try:
        futures = [pool.submit(_worker_tile, job, rows, cols) for rows, cols in tiles]
        for f in as_completed(futures):
            yield f.result()
        finished = True
    except BrokenProcessPool:
        raise worker_died(pool) from None
    finally:
        stop_pool(pool, finished)
