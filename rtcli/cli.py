"""The rtcli command line (README.md, Commands): render, signature, explain, compare, validate, preview,
presets, warmup.

Argument handling only. Errors from the library (RtcliError) and usage errors
become one `error: ...` line on stderr with exit code 2; `--debug` shows the
traceback instead. Ctrl-C (SIGINT) and SIGTERM stop any command at once with
`error: interrupted` and exit code 130 or 143, leaving no file behind.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading

import click

from rtcli import __version__
from rtcli.errors import Interrupted, RtcliError, error_line, one_line, shown

SIZE = click.IntRange(1, 32768)
VIEWS = ("normal", "depth", "uv", "albedo", "bounces", "ids")          # rtcli/inspect/views.py, not imported to start


def _on_signal(signum, frame):
    raise Interrupted(signum)


class RtcliGroup(click.Group):
    """A click group whose errors are one line: 'error: ...', exit 2; no arguments shows the help."""

    def main(self, args=None, prog_name=None, **extra):
        # One BLAS thread: rtcli's parallelism is its worker processes, and OpenBLAS's idle threads
        # spin after each small matrix product of a scene's transforms, taking the workers' cores
        # (whitted at 1920x1080 on 2 cores: 13% more CPU). Set before numpy is first imported.
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
        args = list(sys.argv[1:] if args is None else args)
        extra.pop("standalone_mode", None)
        if not args:
            args = ["--help"]
        restore = _catch_signals()
        try:
            code = super().main(args, prog_name or "rtcli", standalone_mode=False, **extra)
        except click.exceptions.Exit as e:
            sys.exit(e.exit_code)
        except (Interrupted, click.exceptions.Abort) as e:
            if sys.stderr.isatty():
                click.echo(err=True)                   # end the line the terminal's ^C is on
            click.echo("error: interrupted", err=True)
            sys.exit(128 + getattr(e, "signum", signal.SIGINT))
        except click.ClickException as e:
            click.echo(f"error: {one_line(e.format_message())}", err=True)
            sys.exit(2)
        except (RtcliError, MemoryError) as e:
            if "--debug" in args:
                raise
            click.echo(error_line(e), err=True)
            sys.exit(2)
        finally:
            restore()
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise Interrupted(signal.SIGINT) from None


def _catch_signals():
    """Turn SIGTERM into Interrupted (SIGINT is KeyboardInterrupt already); returns the undo."""
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    previous = signal.signal(signal.SIGTERM, _on_signal)
    return lambda: signal.signal(signal.SIGTERM, previous)


@click.group(cls=RtcliGroup, context_settings={"help_option_names": ["-h", "--help"]},
             epilog="The scene format, with every key and default: docs/scene-format.md in the rtcli folder.")
@click.version_option(__version__, prog_name="rtcli")
@click.option("--debug", is_flag=True, help="Show a traceback on errors.")
def main(debug):
    """rtcli: a Whitted ray tracer for YAML scene files.

    Try `rtcli render scenes/whitted.yaml`; `rtcli COMMAND --help` tells more.
    """
    # --debug is honoured by RtcliGroup.main, where errors arrive after click's context has closed.


def _load(path: str, frame: int | None = None, keep: bool = False, lint=None, **overrides):
    """(frames.Loaded, api.Scene) of a scene file at frame `frame` (default 1), with the command
    line's overrides; `keep`: also the files' bytes, for a cluster; `lint` (lint.Lint): what to
    do with its warnings."""
    from rtcli.api.loading import load_file, of_loaded
    loaded = load_file(path, frame, keep=keep, lint=lint is not None and lint.wanted)
    if lint is not None:
        lint.report(loaded.warnings, path, loaded.animation.frames)
    return loaded, of_loaded(loaded, path).override(**overrides)


def _not_empty(ctx, param, value):
    if value is not None and not value.strip():
        raise click.BadParameter("must not be empty", ctx, param)
    return value


def _output(scene_path: str, out: str | None, suffix: str = ".png") -> str:
    return out or os.path.splitext(os.path.basename(scene_path))[0] + suffix


def _check_outputs(outputs, inputs) -> None:
    from rtcli.rendering.outputs import check_outputs
    check_outputs(outputs, inputs)


def _cluster_options(doing: str = "Render on", extra: str = " --workers is then unused."):
    """--cluster, --cluster-file and --local-cluster (README.md, Clusters), their help saying what
    the command does there."""
    def add(command):
        for option in reversed((
                click.option("--cluster", metavar="tcp://HOST:PORT", callback=_not_empty,
                             help=f"{doing} the Dask cluster whose scheduler listens there (needs the extra "
                                  f"`cluster`).{extra}"),
                click.option("--cluster-file", metavar="SCHEDULER.json", callback=_not_empty,
                             help=f"{doing} the Dask cluster named by this scheduler file."),
                click.option("--local-cluster", type=click.IntRange(1, 256), metavar="N",
                             help=f"{doing} a Dask cluster of N worker processes started on this machine."))):
            command = option(command)
        return command
    return add


def _cluster(address, file, local):
    """The cluster the options name (a frames.Reach, to use in a `with` block), or None; rtcli.cluster
    (and Dask) only when one is named. The workers' notes go to stderr above the progress bar."""
    if not (address or file or local):
        return None
    from rtcli import runs
    from rtcli.cluster.renders import Reach
    from rtcli.cluster.target import target
    return Reach(target(address, file, local), runs.note)


@main.command()
@click.argument("scene_files", metavar="SCENE.yaml...", nargs=-1, required=True)
@click.option("-o", "--output", metavar="OUT.png|DIR", callback=_not_empty,
              help="Output image (default: the scene's name .png); the format follows the extension: "
                   ".png, .jpg, .bmp, .tif, .webp or .ppm. Frames: a name with the frame number as %d "
                   "(out/frame_%04d.png); a movie: .apng or .gif. With several scenes or a folder: the "
                   "folder for their images, NAME.png each (default: here).")
@click.option("--width", type=SIZE, help="Image width (the camera is kept).")
@click.option("--height", type=SIZE, help="Image height (the camera is kept).")
@click.option("--block-size", type=click.IntRange(1, 1024), default=1, show_default=True,
              help="Preview: one ray per N x N block, through its top-left pixel.")
@click.option("--samples", type=click.IntRange(1, 16), help="N x N samples per pixel.")
@click.option("--max-depth", type=click.IntRange(1, 64), help="Rays per path, the primary included.")
@click.option("--workers", type=click.IntRange(1, 256), help="Worker processes (default: all cores).")
@click.option("--tile", type=click.IntRange(1, 4096), default=128, show_default=True,
              help="Tile edge in pixels (memory per worker).")
@click.option("--gamma", is_flag=True, help="sRGB-encode the output (default: linear).")
@click.option("--quiet", is_flag=True, help="No progress bar, no warnings.")
@click.option("--progress", is_flag=True, help="Show the progress bar even when stderr is not a terminal.")
@click.option("--stats", is_flag=True, help="Print rays traced by kind, time and rays per second.")
@click.option("--json", "as_json", is_flag=True, help="With --stats: one JSON object per scene, one a line.")
@click.option("--engine", type=click.Choice(["auto", "numpy", "compiled"]), default="auto", show_default=True,
              help="numpy core, or compiled integrator (numba); auto: compiled for big jobs, and for small "
                   "ones with meshes or many spheres once it is compiled.")
@click.option("--no-bvh", is_flag=True, help="No BVH over the scene's objects: test each against every ray (for comparisons).")
@click.option("--view", type=click.Choice(VIEWS), help="Write a debug view instead of the image (default name "
              "NAME.VIEW.png): outward normals, depth, uv, albedo (kd T), bounces or the signature ids.")
@click.option("--frames", "frame_range", metavar="FIRST-LAST",
              help="Render these frames of an animated scene (default with a frame pattern or a movie: all).")
@click.option("--frame", type=click.IntRange(1), metavar="N", help="Render frame N of an animated scene (default 1).")
@click.option("--movie", metavar="MOVIE.apng", callback=_not_empty,
              help="Also write the frames as an animated PNG (.apng) or GIF (.gif).")
@click.option("--skip-existing", is_flag=True, help="Leave the frames (or images) already written at the size "
                                                    "asked for; render the rest.")
@click.option("--strict", is_flag=True, help="The scene's warnings (as validate prints them) are errors (exit 2).")
@click.option("--keep-going", is_flag=True, help="Several scenes or a folder: when one is broken, print its error, "
                                                 "render the others, and exit 2 at the end.")
@_cluster_options()
@click.option("--watch", is_flag=True, help="Render again whenever the scene or a file it reads changes; "
                                            "print each render's time; Ctrl-C ends.")
def render(scene_files, output, width, height, block_size, samples, max_depth, workers, tile,
           gamma, quiet, progress, stats, as_json, engine, no_bvh, view, frame_range, frame, movie, skip_existing,
           strict, keep_going, cluster, cluster_file, local_cluster, watch):
    """Render SCENE.yaml to an image (see docs/scene-format.md for the scene format), or its frames;
    several scenes, or a folder of them, to a folder of images."""
    from rtcli import api, runs
    from rtcli.api.options import check_engine
    from rtcli.rendering import batch
    from rtcli.rendering import frames as animation
    from rtcli.rendering.movie import is_movie
    if as_json and not stats:
        raise click.UsageError("--json goes with --stats")
    if view and stats:
        raise click.UsageError("--stats counts the rays of a render, not of a --view")
    sequence = animation.wants_sequence(output, frame_range, movie)
    several = len(scene_files) > 1 or os.path.isdir(scene_files[0])
    if several and (frame_range or movie or is_movie(output)):
        raise click.UsageError("--frames and movies render one animated scene, not several (--frame N "
                               "renders frame N of each)")
    if view and sequence and not several:
        raise click.UsageError("--view writes one picture: give --frame N, not --frames, a frame pattern "
                               "or a movie")
    if view and (cluster or cluster_file or local_cluster):
        raise click.UsageError("--view is computed on this machine: it takes no cluster option")
    check_engine(engine)
    if watch and several:
        raise click.UsageError("--watch renders one scene file")
    if watch and (sequence or skip_existing):
        raise click.UsageError("--watch renders one image at every change: give --frame N, not --frames, a "
                               "frame pattern, a movie or --skip-existing")
    if watch and (cluster or cluster_file or local_cluster):
        raise click.UsageError("--watch renders on this machine: it takes no cluster option")
    if keep_going and (watch or sequence):
        raise click.UsageError("--keep-going renders the other scenes when one is broken: it takes no --watch, "
                               "--frames, frame pattern or movie")
    if stats:                       # why a machine code file is not used, if one is not
        from rtcli import machinecode
        machinecode.report_to(runs.note)
    where = _cluster(cluster, cluster_file, local_cluster)
    bar = not quiet and (progress or sys.stderr.isatty())
    lint = runs.lint(quiet, strict, several, watch)
    with where or contextlib.nullcontext():
        if sequence and not several:
            job = dict(width=width, height=height, block_size=block_size, tile=tile, gamma=gamma, engine=engine,
                       bvh=not no_bvh)
            shown_stats = ("json" if as_json else "line") if stats else None
            return runs.render_frames(scene_files[0], output, frame_range, frame, movie, skip_existing, where, job,
                                      animation.overrides(samples, max_depth), workers, bar, shown_stats, lint)
        items, folder = batch.plan(list(scene_files), output, f".{view}.png" if view else ".png")
        if skip_existing:
            items = runs.missing(items, width, height)
        current = {}

        def load(path):
            current["loaded"], scene = _load(path, frame, where is not None, lint, samples=samples,
                                             max_depth=max_depth)
            return scene

        def render_one(scene, label, out=None):
            runs.check_size(scene.model, width, height)
            show = runs.progress_bar(bar, one_line(label))
            if view:
                image = runs.view(scene, view, width, height, tile, label if folder is not None else None)
                if out is not None:                               # --watch writes each view itself
                    image.save(out)
                return image
            if where is not None:
                return runs.on_cluster(current["loaded"], scene, where, dict(samples=samples, max_depth=max_depth),
                                   width, height, block_size, tile=tile, gamma=gamma, engine=engine,
                                   bvh=not no_bvh, progress=show)
            return api.render(scene, width=width, height=height, engine=engine, workers=workers,
                              block_size=block_size, tile=tile, gamma=gamma, bvh=not no_bvh, output=out,
                              progress=show, notes=runs.note)
        if watch:
            return runs.watch_scene(items[0], load, render_one, stats, as_json)
        broken = []

        def skip(item, error):
            broken.append(item)
            click.echo(batch.broken_line(item, error), err=True)
        done = batch.run(items, folder, load, render_one, ids=view == "ids",
                         keep_going=skip if keep_going else None) if items else []
    for line in batch.stats_lines(done, as_json, folder is not None) if stats else ():
        click.echo(line)
    if broken:
        raise click.exceptions.Exit(2)


@main.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("-o", "--output", metavar="OUT.png", callback=_not_empty,
              help="Color-coded signature (default: NAME.sig.png).")
@click.option("--ids", "ids_out", metavar="IDS.png", callback=_not_empty,
              help="Also write the raw ids as a 16-bit gray PNG.")
@click.option("--legend", is_flag=True, help="Print id, name, shape and pixels covered.")
@click.option("--width", type=SIZE, help="Image width (the camera is kept).")
@click.option("--height", type=SIZE, help="Image height (the camera is kept).")
@click.option("--block-size", type=click.IntRange(1, 1024), default=1, show_default=True,
              help="One ray per N x N block, through its top-left pixel.")
@click.option("--workers", type=click.IntRange(1, 256), help="Worker processes (default: all cores).")
@click.option("--frame", type=click.IntRange(1), metavar="N", help="Frame N of an animated scene (default 1).")
@_cluster_options()
def signature(scene_file, output, ids_out, legend, width, height, block_size, workers, frame,
              cluster, cluster_file, local_cluster):
    """Write the scene signature: each pixel shows the id of the first object hit (notes 000 11.4)."""
    import numpy as np

    from rtcli import api, runs
    from rtcli.api.pictures import check_ids, legend
    from rtcli.core.display import signature_colors
    from rtcli.rendering.writer import write_images
    where = _cluster(cluster, cluster_file, local_cluster)
    loaded, scene = _load(scene_file, frame, keep=where is not None)
    out = _output(scene_file, output, ".sig.png")
    _check_outputs([(out, False)] + ([(ids_out, True)] if ids_out else []), scene.inputs)
    runs.check_size(scene.model, width, height)
    if where is None:
        ids = api.signature(scene, width=width, height=height, block_size=block_size, workers=workers)
    else:
        check_ids(scene)
        with where:
            ids = runs.on_cluster(loaded, scene, where, dict(samples=None, max_depth=None), width, height, block_size,
                              signature=True)
    write_images([(out, signature_colors(ids))] + ([(ids_out, np.asarray(ids))] if ids_out else []))
    if legend:
        click.echo(f"{'id':>5}  {'name':<24} {'shape':<10} {'pixels':>9}")
        for row in legend(scene, ids):
            click.echo(f"{row.id:>5}  {one_line(row.name) or '-':<24} {row.shape:<10} {row.pixels:>9}")


@main.command(context_settings={"ignore_unknown_options": True})       # a negative X or Y is a pixel, not an option
@click.argument("scene_file", metavar="SCENE.yaml")
@click.argument("x", type=int)
@click.argument("y", type=int)
@click.option("--width", type=SIZE, help="Image width (the camera is kept), as given to render.")
@click.option("--height", type=SIZE, help="Image height (the camera is kept), as given to render.")
@click.option("--samples", type=click.IntRange(1, 16), help="N x N samples per pixel, as given to render.")
@click.option("--max-depth", type=click.IntRange(1, 64), help="Rays per path, as given to render.")
@click.option("--sample", "sample", type=click.IntRange(0), metavar="K",
              help="With N x N samples: show sample K (0 to N*N-1, row by row; default 0).")
@click.option("--all-samples", is_flag=True, help="With N x N samples: show every sample's tree.")
@click.option("--json", "as_json", is_flag=True, help="Print the trees as JSON (every sample unless --sample).")
@click.option("--gamma", is_flag=True, help="The 8-bit value sRGB-encoded, as render --gamma writes it.")
@click.option("--no-bvh", is_flag=True, help="No BVH over the scene's objects, as render --no-bvh.")
@click.option("--frame", type=click.IntRange(1), metavar="N", help="Frame N of an animated scene (default 1).")
def explain(scene_file, x, y, width, height, samples, max_depth, sample, all_samples, as_json, gamma, no_bvh, frame):
    """Explain why pixel (X, Y) has its color: its ray tree, every term of the shading equation
    with its numbers, and the sum at every ray (X from the left, Y from the top, from 0)."""
    from rtcli import runs
    from rtcli.api import explain as explain_pixel
    if sample is not None and all_samples:
        raise click.UsageError("--sample and --all-samples go one at a time")
    _, scene = _load(scene_file, frame)
    runs.check_size(scene.model, width, height)
    scene.override(width=width, height=height)
    e = explain_pixel(scene, x, y, samples=samples, max_depth=max_depth, gamma=gamma, bvh=not no_bvh)
    if sample is not None and sample >= e.samples ** 2:
        raise click.BadParameter(f"{sample} is not a sample of this pixel: it has {e.samples ** 2} "
                                 f"(0 to {e.samples ** 2 - 1})", param_hint="'--sample'")
    if as_json:
        click.echo(e.json(sample))
        return
    color = "NO_COLOR" not in os.environ and None                    # None: click colors only a terminal
    click.echo(e.text(None if all_samples else sample or 0, _style), color=color)


_STYLE_OF = {"ray": dict(fg="cyan", bold=True), "miss": dict(fg="yellow"), "sum": dict(bold=True),
             "note": dict(dim=True), "term": {}}


def _style(text: str, role: str) -> str:
    return click.style(text, **_STYLE_OF[role])


@main.command()
@click.argument("actual", metavar="ACTUAL.png|ACTUAL_DIR")
@click.argument("expected", metavar="EXPECTED.png|EXPECTED_DIR")
@click.option("--diff", metavar="DIFF.png", callback=_not_empty, help="Write a heat map of the difference.")
@click.option("--flip", "flip_out", metavar="FLIP.png", callback=_not_empty,
              help="Also write NVIDIA FLIP's perceptual error map and add its mean to the summary "
                   "(needs flip-evaluator: pip install -e '.[flip]' in the rtcli folder).")
@click.option("--ids", "ids_mode", is_flag=True, help="Compare signature id maps (16-bit gray PNGs).")
@click.option("--tolerance", type=click.IntRange(0, 255), default=2, show_default=True,
              help="A pixel is bad when a channel differs by more than this (of 255).")
@click.option("--max-bad-pixels", type=click.IntRange(0), default=16, show_default=True,
              help="Bad pixels allowed: the larger of this and --max-bad-fraction of the image.")
@click.option("--max-bad-fraction", type=click.FloatRange(0, 1), default=1e-4, show_default=True)
@click.option("--max-cluster", type=click.IntRange(0), default=3, show_default=True,
              help="Largest allowed 8-connected cluster of bad pixels.")
@click.option("--max-boundary-mismatch", type=click.IntRange(0), default=8, show_default=True,
              help="--ids: mismatches allowed on id boundaries (or the fraction below, if larger).")
@click.option("--max-boundary-fraction", type=click.FloatRange(0, 1), default=0.01, show_default=True)
@click.option("--report", "report_dir", metavar="DIR", callback=_not_empty,
              help="Folders: write an HTML report there (index.html and its pictures), worst pair first.")
@click.option("--junit", "junit_file", metavar="FILE", callback=_not_empty,
              help="Folders: write the results as JUnit XML, one test case per pair.")
def compare(actual, expected, diff, flip_out, ids_mode, tolerance, max_bad_pixels, max_bad_fraction,
            max_cluster, max_boundary_mismatch, max_boundary_fraction, report_dir, junit_file):
    """Compare two PNGs' pixels; exit 0 within tolerance, 1 beyond it.

    Given two folders, compare every .png in them paired by relative path: exit 0 when every
    pair passes, 1 when one fails or is missing or extra.
    """
    from rtcli.compare import images as cmp
    from rtcli.rendering.writer import write_images
    id_options = dict(max_boundary_mismatch=max_boundary_mismatch, max_boundary_fraction=max_boundary_fraction)
    image_options = dict(tolerance=tolerance, max_bad_pixels=max_bad_pixels,
                         max_bad_fraction=max_bad_fraction, max_cluster=max_cluster)
    if _folders(actual, expected, diff or flip_out or ids_mode, report_dir or junit_file):
        from rtcli.compare.suite import compare_dirs
        if not compare_dirs(actual, expected, image_options, id_options, report_dir, junit_file, click.echo):
            raise click.exceptions.Exit(1)
        return
    _check_outputs([(p, False) for p in (diff, flip_out) if p], [actual, expected])
    a, e = cmp.read_png(actual), cmp.read_png(expected)
    if ids_mode:
        result = cmp.compare_ids(a, e, **id_options)
    else:
        result = cmp.compare(a, e, image_options, id_options)
    summary = result.summary
    comparable = a.shape == e.shape and a.ndim == 3            # pictures of the same size
    pictures = []
    if diff and comparable:
        pictures.append((diff, cmp.heat_map(a, e, tolerance)))
    if flip_out and comparable:
        picture, mean = cmp.flip_map(a, e)
        pictures.append((flip_out, picture))
        summary += f", mean FLIP {mean:.4f}"
    write_images(pictures)
    click.echo(summary)
    if not result.ok:
        raise click.exceptions.Exit(1)


def _folders(actual: str, expected: str, pair_options, folder_options) -> bool:
    """Whether compare is given two folders; a usage error for a folder and a file, or for options
    of the other mode."""
    from rtcli.compare.suite import are_folders
    folders = are_folders(actual, expected)
    if folders and pair_options:
        raise click.UsageError("--diff, --flip and --ids compare two images; two folders get --report")
    if not folders and folder_options:
        raise click.UsageError("--report and --junit compare two folders")
    return folders


@main.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("--objects", "list_objects", is_flag=True,
              help="List every object: id, name, shape, material, shadow, triangles, world-space bounds.")
@click.option("--strict", is_flag=True, help="Warnings are errors (exit 2).")
def validate(scene_file, list_objects, strict):
    """Parse and check a scene, every frame of an animated one; print a summary, and warnings about
    likely mistakes on stderr. Renders only a small signature (does the camera see anything?)."""
    from rtcli.api.loading import load_file
    from rtcli.inspect import checks, lint
    from rtcli.scenefile.build import summary
    loaded = load_file(scene_file, lint=True)
    frames = loaded.animation.check_all()
    scene, found = loaded.scene, loaded.warnings
    if strict and found:
        raise checks.strict_error(found)
    click.echo(f"{shown(scene_file)}: ok: {summary(scene)}{frames}")
    if list_objects:
        for line in checks.object_lines(checks.object_rows(scene)):
            click.echo(line)
    for line in lint.lines(found, scene_file, loaded.animation.frames):
        click.echo(line, err=True)


@main.command()
@_cluster_options("Warm every worker of", " This machine is not warmed.")
def warmup(cluster, cluster_file, local_cluster):
    """Compile the render engine now (about a minute, once), or load it from numba's cache; say
    where the cache is and how long it took. Renders then start at once. With a cluster option:
    on every worker of the cluster at once, a line for each."""
    import time

    where = _cluster(cluster, cluster_file, local_cluster)
    if where is not None:
        from rtcli.cluster.warm import warm
        with where:
            return warm(where.session(), click.echo)
    from rtcli import machinecode, variants
    from rtcli.compiled.warmup import bytecode
    from rtcli.compiled.warmup import warmup as warm
    start = time.perf_counter()
    machinecode.report_to(lambda text: click.echo(f"note: {text}", err=True))
    where = variants.cache_location() if variants.ENABLED else None
    if where is not None:
        click.echo(f"cache: {where} ({where.why})" if where.enabled else f"cache: none ({where.why}); "
                   f"set {variants.CACHE_ENV} to a writable folder")
    done, (files, why) = warm(notes=lambda text: click.echo(f"note: {text}", err=True))
    for what, load in done:
        how = f"compiled in {load.compile_seconds:.1f} s" if load.compile_seconds else "loaded from the cache"
        click.echo(f"{what}: {how}, ready in {load.seconds:.2f} s")
    click.echo(f"machine code files: {', '.join(files) or 'none'} in {machinecode.folder()}" +
               (" (renders start without numba)" if files else "") + (f"; not written: {why}" if why else ""))
    if not bytecode():
        click.echo("note: rtcli's folder is read-only: its Python files were not compiled to bytecode", err=True)
    compiled = sum(load.compile_seconds for _, load in done)
    click.echo(f"{'compiled' if compiled else 'warm: nothing to compile'}; {time.perf_counter() - start:.2f} s in all")


@main.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("--port", type=click.IntRange(0, 65535), default=0, show_default=True,
              help="The port to serve on (0: any free one).")
@click.option("--host", default="127.0.0.1", show_default=True, callback=_not_empty,
              help="The address to serve on; another than 127.0.0.1 is warned about.")
@click.option("--no-browser", is_flag=True, help="Print the URL only; do not open a browser.")
@click.option("--width", type=SIZE, help="Image width (the camera is kept).")
@click.option("--height", type=SIZE, help="Image height (the camera is kept).")
@click.option("--samples", type=click.IntRange(1, 16), help="N x N samples per pixel.")
@click.option("--max-depth", type=click.IntRange(1, 64), help="Rays per path, the primary included.")
@click.option("--engine", type=click.Choice(["auto", "numpy", "compiled"]), default="auto", show_default=True,
              help="As for render.")
@click.option("--gamma", is_flag=True, help="sRGB-encode the picture (default: linear).")
@click.option("--no-bvh", is_flag=True, help="No BVH over the scene's objects.")
@click.option("--workers", type=click.IntRange(1, 256), help="Threads tracing tiles with the compiled engine "
                                                             "(default: all cores).")
@click.option("--frame", type=click.IntRange(1), default=1, metavar="N", help="Start at frame N of an animated scene.")
@click.option("--against", metavar="GOLDEN.png", callback=_not_empty,
              help="Compare each finished render with this image: heat map, slider, FLIP where installed.")
@click.option("--tev", metavar="HOST:PORT", callback=_not_empty,
              help="Also stream the tiles and views to the tev viewer listening there (its default: 127.0.0.1:14158).")
def preview(scene_file, port, host, no_browser, width, height, samples, max_depth, engine, gamma, no_bvh, workers,
            frame, against, tev):
    """Serve a live preview of SCENE.yaml in the browser: it renders coarse to fine, renders again at
    every save of the scene or a file it reads, and explains the pixel clicked. Ctrl-C ends it
    (docs/preview.md). Needs the extra `preview`: pip install -e '.[preview]' in the rtcli folder."""
    from rtcli import runs
    from rtcli.api.options import check_engine
    from rtcli.preview import Options, serve
    check_engine(engine)
    options = Options(width, height, samples, max_depth, engine, gamma, not no_bvh, frame, workers)
    serve(scene_file, options, host=host, port=port, browser=not no_browser, against=against, tev=tev,
          url=lambda text: click.echo(text), say=runs.stamped)


@main.command()
def presets():
    """List the material presets (McReynolds and Blythe) with their coefficients."""
    from rtcli.scenefile.presets import table_rows
    for row in table_rows():
        click.echo(row)
