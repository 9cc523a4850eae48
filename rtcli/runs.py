"""How `rtcli render` (and `signature`) carry out what the options ask (README.md, Commands):
the image size with its note, the progress bar, the scene's warnings, an animation's frames, a
still traced on a cluster, a watch, a debug view. cli.py parses the options and calls these.
"""

from __future__ import annotations

import os
import threading
import time

import click

from rtcli.errors import one_line, shown
from rtcli.rendering.outputs import check_outputs


def size(model, width, height) -> tuple[int, int]:
    """The image size of a scene's model (api.image_size with the options' names), its note printed."""
    w, h, note = check_size(model, width, height)
    if note:
        click.echo(f"note: {note}", err=True)
    return w, h


def check_size(model, width, height) -> tuple[int, int, str | None]:
    """api.image_size, its errors naming the options --width and --height."""
    from rtcli.api.options import image_size
    return image_size(model, width, height, ("--width", "--height"))


_terminal = threading.Lock()          # the progress bar and the notes share stderr's last line
_bar_open = [False]                   # a progress bar's line is on stderr, not ended yet


def progress_bar(enabled: bool, label: str):
    if not enabled:
        return None

    def show(done, total):
        bar = "#" * (30 * done // total)
        with _terminal:
            click.echo(f"\r{label} [{bar:<30}] {100 * done // total:3d}%", err=True, nl=done == total)
            _bar_open[0] = done != total
    return show


def note(text: str) -> None:
    """A `note:` line on stderr, from any thread (a cluster's workers speak while the render runs):
    below a progress bar's unfinished line, the bar going on on the next line."""
    with _terminal:
        click.echo(("\n" if _bar_open[0] else "") + f"note: {text}", err=True)
        _bar_open[0] = False


def lint(quiet: bool, strict: bool, several: bool, watch: bool):
    """What render does with a scene's warnings (lint.Lint): printed on stderr (after the time
    in a watch, as its other lines), hidden by --quiet, errors with --strict."""
    from rtcli.inspect.lint import Lint
    return Lint(stamped if watch else echo_err, quiet, strict, several)


def echo_err(line: str) -> None:
    click.echo(line, err=True)


def stamped(line: str) -> None:
    """A watch's line on stderr, after the time of day, as its renders' lines."""
    click.echo(f"{clock()} {line}", err=True)


def clock() -> str:
    """The time of day, HH:MM:SS, that begins a watch's lines."""
    return time.strftime("%H:%M:%S")


def make_job(model, width, height, block_size, **kw):
    from rtcli.rendering.tiles import Job
    return Job(*size(model, width, height), block_size, **kw)


def on_cluster(loaded, scene, where, changes: dict, width, height, block_size, progress=None, **kw):
    """The still of `loaded` traced on the cluster (rtcli/cluster/renders.py), as api.render returns it."""
    from rtcli.api.results import ImageArray, RenderStats
    from rtcli.cluster.renders import still
    from rtcli.rendering.frames import overrides
    job = make_job(scene.model, width, height, block_size, **kw)
    start = time.perf_counter()
    pixels, counts = still(where, loaded, job, progress, overrides(**changes))
    s = scene.model.settings
    stats = RenderStats.of(job.width, job.height, 1 if job.signature else s.samples, counts,
                           time.perf_counter() - start, start_up=False)
    return ImageArray(pixels, stats, scene.inputs)


def render_frames(scene_file: str, output, frame_range, frame, movie, skip_existing: bool, where, job: dict,
                  changes: dict, workers, bar: bool, stats, lint=None) -> None:
    """An animation's frames to files or movies (frames.py), each file written as its frame is done;
    `stats`: None, "line" or "json"; `lint` (lint.Lint): what to do with the scene's warnings."""
    from rtcli.api.loading import load_file
    from rtcli.rendering import batch
    from rtcli.rendering import frames as animation
    start = time.perf_counter()
    loaded = load_file(scene_file, None, keep=where is not None, lint=lint is not None and lint.wanted)
    if lint is not None:
        lint.report(loaded.warnings, scene_file, loaded.animation.frames)
    seq = animation.sequence(loaded.animation, scene_file, output, frame_range, frame, movie)
    folder = os.path.dirname(os.path.abspath(next(iter(seq.paths.values())))) if seq.paths else None
    made = batch.make_folder(folder)                     # a frame pattern's folder (its parent must exist)
    try:
        check_outputs([(p, False) for p in seq.paths.values()] + [(m, "movie") for m in seq.movies], loaded.inputs)
        _render_sequence(loaded, seq, scene_file, changes, workers, bar, stats, where, job, skip_existing, start)
    except BaseException:
        if made:
            batch.remove_folder(folder)                  # only when empty: frames written stay
        raise


def _render_sequence(loaded, seq, scene_file: str, changes: dict, workers, bar: bool, stats, where, job: dict,
                     skip_existing: bool, start: float) -> None:
    import json

    from rtcli.api.results import RenderStats
    from rtcli.cluster.renders import frames as cluster_frames
    from rtcli.rendering import frames as animation
    scene = loaded.scene
    animation.apply(scene, changes)            # the other frames are checked as written, then changed alike
    size = job.pop("width"), job.pop("height"), job.pop("block_size")
    job = make_job(scene, *size, **job)
    show = progress_bar(bar, one_line(os.path.basename(scene_file)))
    todo, rendering = animation.to_render(seq, skip_existing, job), time.perf_counter()
    if where is None:
        frames = lambda todo: animation.local_frames(loaded, todo, job, workers or os.cpu_count() or 1, changes, show)
    else:
        frames = lambda todo: cluster_frames(where, loaded, todo, job, changes, show)
    counts = animation.render_sequence(loaded, seq, job, skip_existing, frames)
    if not stats:
        return
    done = RenderStats.of(job.width, job.height, scene.settings.samples, counts, time.perf_counter() - rendering,
                          start_up=False)
    seconds = time.perf_counter() - start
    if stats == "json":
        click.echo(json.dumps({"scene": scene_file, "frames": todo, **done.as_dict(),
                               "wall_seconds": round(seconds, 6)}))
    else:
        click.echo(done.line(seconds))


def watch_scene(item, load, render_one, stats: bool, as_json: bool) -> None:
    """render --watch: the scene to its image now and after every change, until Ctrl-C. With
    --json, stdout holds only the JSON lines (the watch's own lines go to stderr)."""
    from rtcli.rendering import batch
    from rtcli.rendering.outputs import check_file_output
    from rtcli.rendering.watch import watch
    check_file_output(item.output, [item.scene])        # the scene as its own output: refused at once

    def once() -> None:
        start = time.perf_counter()
        image = render_one(load(item.scene), os.path.basename(item.scene), item.output)
        seconds = time.perf_counter() - start
        click.echo(f"{clock()} rendered {shown(item.output)} ({image.shape[1]}x{image.shape[0]}) "
                   f"in {seconds:.2f} s", err=as_json)
        for line in batch.stats_lines([(item, image.stats, seconds)], as_json, False) if stats else ():
            click.echo(line)
    click.echo(f"watching {shown(item.scene)} and the files it reads; Ctrl-C ends", err=as_json)
    watch(item.scene, once, stamped)


def missing(items: list, width, height) -> list:
    """--skip-existing with several scenes: the items (batch.Item) without an image of the size the
    scene renders at (an image of another size is rendered again). A scene whose image exists is
    loaded to learn its size; one that fails to load stays in, to fail where it renders."""
    from rtcli.api.loading import load_file
    from rtcli.errors import RtcliError
    from rtcli.rendering.frames import has_image
    todo = []
    for item in items:
        if os.path.isfile(item.output):
            try:
                w, h, _ = check_size(load_file(item.scene).scene, width, height)
            except RtcliError:
                w = h = 0
            if w and has_image(item.output, w, h):
                continue
        todo.append(item)
    return todo


def view(scene, kind: str, width, height, tile: int, label: str | None):
    """A debug view's picture (rtcli/inspect/views.py), its summary line printed; the ids view as its id
    map, which `rtcli compare --ids` reads (README.md, Commands)."""
    from rtcli.api import view
    from rtcli.api.results import ImageArray
    from rtcli.inspect.views import summary
    data = view(scene, kind, width=width, height=height, tile=tile)
    click.echo((f"{one_line(label)}: " if label else "") + summary(data, kind, scene.model.settings.max_depth))
    return data if data.is_ids else ImageArray(data.to_8bit(), inputs=scene.inputs)
