"""`rtcli render` of an animation's frames (README.md, Animation): to files named by the frame
number, or to a movie, here or on a cluster, each file written as its frame is done
(rtcli/rendering/frames.py)."""

from __future__ import annotations

import json
import os
import time

import click

from rtcli.api.loading import load_file
from rtcli.api.results import RenderStats
from rtcli.cli.options import check_outputs
from rtcli.cli.terminal import progress_bar, size
from rtcli.cluster.renders import frames as cluster_frames
from rtcli.errors import one_line
from rtcli.rendering import batch
from rtcli.rendering import frames as animation
from rtcli.rendering.tiles import Job


def run(o, where, lint) -> None:
    """The frames the options (render.Options) ask for, on the cluster `where` (a Reach) or here;
    `lint` (inspect.lint.Lint): what to do with the scene's warnings."""
    start = time.perf_counter()
    scene_file = o.scene_files[0]
    loaded = load_file(scene_file, None, keep=where is not None, lint=lint.wanted)
    lint.report(loaded.warnings, scene_file, loaded.animation.frames)
    seq = animation.sequence(loaded.animation, scene_file, o.output, o.frame_range, o.frame, o.movie)
    folder = os.path.dirname(os.path.abspath(next(iter(seq.paths.values())))) if seq.paths else None
    made = batch.make_folder(folder)                     # a frame pattern's folder (its parent must exist)
    try:
        check_outputs([(p, False) for p in seq.paths.values()] + [(m, "movie") for m in seq.movies], loaded.inputs)
        _render(o, loaded, seq, where, start)
    except BaseException:
        if made:
            batch.remove_folder(folder)                  # only when empty: frames written stay
        raise


def _render(o, loaded, seq, where, start: float) -> None:
    scene, changes = loaded.scene, o.changes
    animation.apply(scene, changes)            # the other frames are checked as written, then changed alike
    job = Job(*size(scene, o.width, o.height), o.block_size, tile=o.tile, gamma=o.gamma, engine=o.engine,
              bvh=not o.no_bvh)
    show = progress_bar(o.bar, one_line(os.path.basename(o.scene_files[0])))
    todo, rendering = animation.to_render(seq, o.skip_existing, job), time.perf_counter()
    if where is None:
        workers = o.workers or os.cpu_count() or 1
        frames = lambda todo: animation.local_frames(loaded, todo, job, workers, changes, show)
    else:
        frames = lambda todo: cluster_frames(where, loaded, todo, job, changes, show)
    counts = animation.render_sequence(loaded, seq, job, o.skip_existing, frames)
    if not o.stats:
        return
    done = RenderStats.of(job.width, job.height, scene.settings.samples, counts, time.perf_counter() - rendering,
                          start_up=False)
    seconds = time.perf_counter() - start
    if o.as_json:
        click.echo(json.dumps({"scene": o.scene_files[0], "frames": todo, **done.as_dict(),
                               "wall_seconds": round(seconds, 6)}))
    else:
        click.echo(done.line(seconds))
