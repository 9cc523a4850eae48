"""The picture coarse to fine: the block-size preview of notes 002 as the first passes of the render.

Pass B traces one ray per B x B block, through the block's top-left pixel, and gives the
whole block its color, as `rtcli render --block-size B` does. The passes go B = 16, 8, 4,
2, 1, and each refines the last: the grid points of pass B that pass 2B traced already
(both coordinates multiples of 2B) keep their color, so pass B traces only the other
three quarters of its grid. Every pixel is traced once in all (W x H rays, as a plain
render), and after pass B the image is, byte for byte, the one `--block-size B` renders.

The passes are cut into tiles of about TILE_RAYS rays (rendering/tiles.py's tiles are bigger: here a
tile is what a new edit waits for before the render stops), each traced by rendering/tiles.py's
render_tile with the engine tiles.prepare picked, and handed on as soon as it is done.
The compiled engine traces a pass's tiles in several threads at once (Progressive).
"""

from __future__ import annotations

import dataclasses
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass

import numpy as np

from rtcli.core.display import to_8bit
from rtcli.rendering.engine import prepare
from rtcli.rendering.tiles import Job, blank, place, render_tile
from rtcli.stats import Stats

PASSES = (16, 8, 4, 2, 1)          # one ray per B x B block, pass by pass
TILE_RAYS = 4096                   # rays per tile, about (a tile's edge: 64 grid points at one sample)


@dataclass(frozen=True)
class Tile:
    """A tile of a pass, done: its grid points' colors, each standing for a block x block block."""

    block: int                     # the pass: one ray per block x block pixels
    rows: np.ndarray               # the pass's grid rows in the tile (multiples of block), top to bottom
    cols: np.ndarray               # its grid columns
    pixels: np.ndarray             # uint8 (len(rows), len(cols), 3): the grid points' 8-bit colors
    colors: np.ndarray             # float64, same shape: their linear colors, as traced (averaged over samples)
    last: bool                     # the last tile of its pass


@dataclass
class Progress:
    """How far the render is: pixels traced (each once in all), the pass, the seconds since it began."""

    traced: int = 0
    pixels: int = 0
    block: int = PASSES[0]
    seconds: float = 0.0

    @property
    def eta(self) -> float | None:
        """Seconds left at the pace so far (None before anything is traced)."""
        if not self.traced:
            return None
        return self.seconds * (self.pixels - self.traced) / self.traced


def passes(width: int, height: int) -> list[int]:
    """The passes' block sizes: from 16 down to 1, without the blocks as big as the image itself
    (a one-block pass shows one color)."""
    return [b for b in PASSES if b == 1 or b < max(width, height)]


def grid_tiles(width: int, height: int, block: int, samples: int = 1) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Pass `block`'s grid (every block-th row and column) in tiles of about TILE_RAYS rays,
    row by row from the top: (rows, cols) each."""
    rows, cols = np.arange(0, height, block), np.arange(0, width, block)
    edge = max(1, int(np.sqrt(TILE_RAYS)) // samples)
    for r in range(0, len(rows), edge):
        for c in range(0, len(cols), edge):
            yield rows[r:r + edge], cols[c:c + edge]


def new_points(rows: np.ndarray, cols: np.ndarray, block: int, first: bool) -> np.ndarray:
    """Which grid points of the tile a pass traces, a (len(rows), len(cols)) mask: all of them in
    the first pass; later, those the previous pass (2 block) did not (a coordinate not a multiple
    of 2 block)."""
    if first:
        return np.ones((len(rows), len(cols)), dtype=bool)
    return ~((rows % (2 * block) == 0)[:, None] & (cols % (2 * block) == 0)[None, :])


class Progressive:
    """One render of a scene's model, pass by pass: tiles() traces them; `image` (8-bit) and
    `linear` (float) hold the picture so far, each pixel the color of the block it is in.

    With the compiled engine, `threads` threads trace a pass's tiles at once, each with a twin
    of the engine (Compiled.twin); the numpy engine traces in the caller's thread. Either way
    the tiles are placed in the caller's thread, as they come, and a pass begins once the last
    is done (its grid points' colors are the next pass's old points)."""

    def __init__(self, model, job: Job, notes: Callable[[str], None] | None = None, threads: int = 1):
        self.model, self.job = model, job
        self.blocks = passes(job.width, job.height)
        self.image = blank(job)
        self.linear = np.zeros(self.image.shape)
        self.stats, self.progress = Stats(), Progress(pixels=job.width * job.height, block=self.blocks[0])
        samples = model.settings.samples
        self.engine, load = prepare(model, job, job.width * job.height * samples * samples, notes)
        self.stats.engine = "compiled" if self.engine else "numpy"
        if load:
            self.stats.load_seconds, self.stats.compile_seconds = load.seconds, load.compile_seconds
        self.threads = threads if self.engine else 1

    def tiles(self) -> Iterator[Tile]:
        """Trace the passes tile by tile, each tile placed in the image before it is yielded. Stop
        early by closing the generator: the tiles in flight are waited for, the rest not begun."""
        start, samples = time.perf_counter(), self.model.settings.samples
        pool = self._pool() if self.threads > 1 else None
        try:
            for k, block in enumerate(self.blocks):
                self.progress.block = block
                todo = [(rows, cols, new_points(rows, cols, block, k == 0))
                        for rows, cols in grid_tiles(self.job.width, self.job.height, block, samples)]
                for n, (rows, cols, new, traced) in enumerate(self._traced(pool, todo), 1):
                    tile = self._place(block, rows, cols, new, traced, n == len(todo))
                    self.progress.seconds = time.perf_counter() - start
                    yield tile
        finally:
            if pool is not None:
                pool.shutdown(wait=True, cancel_futures=True)

    def _pool(self) -> ThreadPoolExecutor:
        own = threading.local()

        def twin() -> None:
            own.engine = self.engine.twin()
        self._own = own
        return ThreadPoolExecutor(self.threads, "rtcli-tile", initializer=twin)

    def _traced(self, pool, todo: list):
        """(rows, cols, new, (colors, stats)) of each tile, its new points traced: in order here,
        or as the pool's threads finish them."""
        if pool is None:
            for rows, cols, new in todo:
                yield rows, cols, new, self._trace(self.engine, rows, cols, new)
            return
        futures = {pool.submit(lambda *a: self._trace(self._own.engine, *a), rows, cols, new): (rows, cols, new)
                   for rows, cols, new in todo}
        try:
            for done in as_completed(futures):
                yield (*futures[done], done.result())
        finally:
            for future in futures:
                future.cancel()

    def _trace(self, engine, rows: np.ndarray, cols: np.ndarray, new: np.ndarray):
        """The linear colors (n, 3) of the tile's new points, and the stats of tracing them."""
        jj, ii = (a[new] for a in np.meshgrid(rows, cols, indexing="ij"))
        if not len(ii):
            return np.zeros((0, 3)), Stats()
        return render_tile(self.model, self.job, ii, jj, engine)

    def _place(self, block: int, rows, cols, new, traced, last: bool) -> Tile:
        """Place a tile's grid, its new points' colors with the old points' (traced before), over
        their blocks; the Tile."""
        colors, stats = traced
        grid_colors = self.linear[rows][:, cols]
        grid_pixels = self.image[rows][:, cols]
        grid_colors[new], grid_pixels[new] = colors, to_8bit(colors, self.job.gamma)
        self.stats.add(stats)
        self.progress.traced += len(colors)
        job = dataclasses.replace(self.job, block_size=block)
        place(self.image, job, rows, cols, grid_pixels)
        place(self.linear, job, rows, cols, grid_colors)
        return Tile(block, rows, cols, grid_pixels, grid_colors, last)
