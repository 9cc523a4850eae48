"""`rtcli render` of one scene or many, each to an image (README.md, Commands): here or on a
cluster, its debug view instead with --view, the others on with --keep-going, only the missing
ones with --skip-existing, once, or again at every save with --watch."""

from __future__ import annotations

import os
import time

import click

from rtcli import api
from rtcli.api.layers import layers_of, meta_of, needs_floats
from rtcli.api.loading import load_file
from rtcli.api.results import ImageArray, RenderStats
from rtcli.cli.options import check_size, load
from rtcli.cli.terminal import clock, note, progress_bar, size, stamped
from rtcli.cluster.renders import still
from rtcli.errors import RtcliError, one_line, shown
from rtcli.inspect.views import summary
from rtcli.rendering import batch
from rtcli.rendering import watch as watching
from rtcli.rendering.frames import has_image
from rtcli.rendering.outputs import check_file_output, check_format_options
from rtcli.rendering.tiles import Job


def run(o, where, lint) -> list:
    """Render the scenes the options (render.Options) name, each to its image, on the cluster
    `where` (a Reach) or here; their stats lines after. Returns the scenes left out as broken."""
    items, folder = batch.plan(list(o.scene_files), o.output, f".{o.view}.png" if o.view else ".png")
    if o.skip_existing:
        items = missing(items, o.width, o.height)
    current, targets = {}, {item.scene: item.output for item in items}
    for item in items:
        check_format_options(item.output, layers=o.layers, alpha=o.alpha, **o.write)

    def load_one(path):
        current["loaded"], scene = load(path, o.frame, where is not None, lint, samples=o.samples,
                                        max_depth=o.max_depth)
        return scene

    def render_one(scene, label, out=None):
        return one_image(o, scene, label, out, folder, where, current.get("loaded"), targets.get(scene.source))
    if o.watch:
        return watch_scene(items[0], load_one, render_one, o.stats, o.as_json)
    broken = []

    def skip(item, error):
        broken.append(item)
        click.echo(batch.broken_line(item, error), err=True)
    done = batch.run(items, folder, load_one, render_one, ids=o.view == "ids", write=o.write,
                     keep_going=skip if o.keep_going else None) if items else []
    for line in batch.stats_lines(done, o.as_json, folder is not None) if o.stats else ():
        click.echo(line)
    return broken


def one_image(o, scene, label: str, out, folder, where, loaded, target=None):
    """The image (or view) of one loaded scene; written to `out` when given (else by the caller, to
    `target`, as o.write says: the image is then linear when that output takes floats)."""
    check_size(scene.model, o.width, o.height)
    show = progress_bar(o.bar, one_line(label))
    if o.view:
        image = view(scene, o.view, o.width, o.height, o.tile, label if folder is not None else None)
        if out is not None:                               # --watch writes each view itself
            image.save(out)
        return image
    alpha = o.alpha or scene.model.settings.alpha
    check_format_options(out or target or "", layers=o.layers, alpha=alpha, **o.write)
    floats = out is None and needs_floats(target, int(o.bit_depth))
    if where is not None:
        image = on_cluster(loaded, scene, where, o.changes, o.width, o.height, o.block_size, tile=o.tile,
                           gamma=o.gamma and not floats, engine=o.engine, bvh=not o.no_bvh, progress=show,
                           linear=floats, alpha=alpha)
        if o.layers:
            image.layers = layers_of(scene, o.layers, image.shape[1], image.shape[0], o.tile, o.workers or 1)
        return image
    files = {"bit_depth": int(o.bit_depth), "half": o.half} if out is not None else {}    # --watch writes it
    return api.render(scene, width=o.width, height=o.height, engine=o.engine, workers=o.workers,
                      block_size=o.block_size, tile=o.tile, gamma=o.gamma and not floats, bvh=not o.no_bvh,
                      linear=floats, alpha=alpha, layers=o.layers, output=out, progress=show, notes=note, **files)


def on_cluster(loaded, scene, where, changes: dict, width, height, block_size, progress=None, **kw):
    """The still of `loaded` traced on the cluster (rtcli/cluster/renders.py), as api.render returns it."""
    job = Job(*size(scene.model, width, height), block_size, **kw)
    start = time.perf_counter()
    pixels, counts = still(where, loaded, job, progress, changes)
    s = scene.model.settings
    seconds = time.perf_counter() - start
    stats = RenderStats.of(job.width, job.height, 1 if job.signature else s.samples, counts, seconds, start_up=False)
    meta = meta_of(scene, job.width, job.height, block_size=block_size, gamma=job.gamma, alpha=job.alpha,
                   content="ids" if job.signature else "color", engine=stats.engine, seconds=seconds)
    return ImageArray(pixels, stats, scene.inputs, meta=meta)


def watch_scene(item, load_one, render_one, stats: bool, as_json: bool) -> list:
    """render --watch: the scene to its image now and after every change, until Ctrl-C. With
    --json, stdout holds only the JSON lines (the watch's own lines go to stderr)."""
    check_file_output(item.output, [item.scene])        # the scene as its own output: refused at once

    def once() -> None:
        start = time.perf_counter()
        image = render_one(load_one(item.scene), os.path.basename(item.scene), item.output)
        seconds = time.perf_counter() - start
        click.echo(f"{clock()} rendered {shown(item.output)} ({image.shape[1]}x{image.shape[0]}) "
                   f"in {seconds:.2f} s", err=as_json)
        for line in batch.stats_lines([(item, image.stats, seconds)], as_json, False) if stats else ():
            click.echo(line)
    click.echo(f"watching {shown(item.scene)} and the files it reads; Ctrl-C ends", err=as_json)
    watching.watch(item.scene, once, stamped)
    return []


def missing(items: list, width, height) -> list:
    """--skip-existing with several scenes: the items (batch.Item) without an image of the size the
    scene renders at (an image of another size is rendered again). A scene whose image exists is
    loaded to learn its size; one that fails to load stays in, to fail where it renders."""
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
    data = api.view(scene, kind, width=width, height=height, tile=tile)
    click.echo((f"{one_line(label)}: " if label else "") + summary(data, kind, scene.model.settings.max_depth))
    if data.is_ids:
        return data
    meta = meta_of(scene, data.shape[1], data.shape[0], content=f"view {kind}", engine="numpy")
    return ImageArray(data.to_8bit(), inputs=scene.inputs, meta=meta)
