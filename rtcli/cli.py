"""The rtcli command line (README.md, Commands): render, signature, compare, validate, presets.

Argument handling only. Errors from the library (RtcliError) and usage errors
become one `error: ...` line on stderr with exit code 2; `--debug` shows the
traceback instead. Ctrl-C (SIGINT) and SIGTERM stop any command at once with
`error: interrupted` and exit code 130 or 143, leaving no file behind.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

import click

from rtcli import __version__
from rtcli.errors import Interrupted, RtcliError, one_line, shown

SIZE = click.IntRange(1, 32768)
INSTALL = "pip install -e '.[{extra}]' in the rtcli folder (rtcli is not on the package index)"


def _on_signal(signum, frame):
    raise Interrupted(signum)


class RtcliGroup(click.Group):
    """A click group whose errors are one line: 'error: ...', exit 2; no arguments shows the help."""

    def main(self, args=None, prog_name=None, **extra):
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
            click.echo(f"error: {one_line(str(e) or 'out of memory')}", err=True)
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


def _not_empty(ctx, param, value):
    if value is not None and not value.strip():
        raise click.BadParameter("must not be empty", ctx, param)
    return value


def _output(scene_path: str, out: str | None, suffix: str = ".png") -> str:
    return out or os.path.splitext(os.path.basename(scene_path))[0] + suffix


def _check_outputs(outputs, inputs) -> None:
    from rtcli.outputs import check_outputs
    check_outputs(outputs, inputs)


def _size(scene, width, height) -> tuple[int, int]:
    """The image size: the scene's, with --width or --height alone keeping its aspect ratio."""
    from rtcli.scenefile.build import camera_form, check_image_size
    sw, sh = scene.settings.width, scene.settings.height
    w = width or (max(1, round(height * sw / sh)) if height else sw)
    h = height or (max(1, round(width * sh / sw)) if width else sh)
    for given, name, other, value in ((width, "--width", "height", h), (height, "--height", "width", w)):
        if given and value > 32768:
            raise RtcliError(f"{name} {given} makes the {other} {value} (keeping the scene's {sw}x{sh} "
                             "aspect ratio), more than 32768")
    if (why := check_image_size(w, h)) is not None:
        raise RtcliError(why)
    form = camera_form(scene)
    if width and height and w * sh != h * sw and form != "fov":
        click.echo(f"note: the {form} camera keeps its rectangle, so the {sw}x{sh} scene stretches "
                   f"to {w}x{h}", err=True)
    return w, h


def _job(scene, width, height, block_size, **kw):
    from rtcli.render import Job
    return Job(*_size(scene, width, height), block_size, **kw)


def _check_engine(engine: str) -> None:
    from rtcli import variants
    if engine == "compiled" and not variants.ENABLED:
        raise RtcliError(f"--engine compiled needs numba: {INSTALL.format(extra='fast')}")


def _progress(enabled: bool, label: str):
    if not enabled:
        return None

    def show(done, total):
        bar = "#" * (30 * done // total)
        click.echo(f"\r{label} [{bar:<30}] {100 * done // total:3d}%", err=True, nl=done == total)
    return show


def _cluster_options(command):
    """--cluster, --cluster-file and --local-cluster (README.md, Clusters)."""
    for option in reversed((
            click.option("--cluster", metavar="tcp://HOST:PORT", callback=_not_empty,
                         help="Render on the Dask cluster whose scheduler listens there (needs the extra "
                              "`cluster`; --workers is then unused)."),
            click.option("--cluster-file", metavar="SCHEDULER.json", callback=_not_empty,
                         help="Render on the Dask cluster named by this scheduler file."),
            click.option("--local-cluster", type=click.IntRange(1, 256), metavar="N",
                         help="Render on a Dask cluster of N worker processes started on this machine."))):
        command = option(command)
    return command


def _cluster(address, file, local):
    """The cluster the options name, or None; rtcli.cluster (and Dask) only when one is named."""
    if not (address or file or local):
        return None
    from rtcli.cluster import target
    return target(address, file, local)


@main.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("-o", "--output", metavar="OUT.png", callback=_not_empty,
              help="Output image (default: the scene's name .png); the format follows the extension: "
                   ".png, .jpg, .bmp, .tif, .webp or .ppm. Frames: a name with the frame number as %d "
                   "(out/frame_%04d.png); a movie: .apng or .gif.")
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
@click.option("--quiet", is_flag=True, help="No progress bar.")
@click.option("--progress", is_flag=True, help="Show the progress bar even when stderr is not a terminal.")
@click.option("--stats", is_flag=True, help="Print rays traced by kind, time and rays per second.")
@click.option("--engine", type=click.Choice(["auto", "numpy", "compiled"]), default="auto", show_default=True,
              help="numpy core, or compiled integrator (numba); auto: compiled for big jobs it can render.")
@click.option("--no-bvh", is_flag=True, help="No BVH over the scene's objects: test each against every ray (for comparisons).")
@click.option("--frames", "frame_range", metavar="FIRST-LAST",
              help="Render these frames of an animated scene (default with a frame pattern or a movie: all).")
@click.option("--frame", type=click.IntRange(1), metavar="N", help="Render frame N of an animated scene (default 1).")
@click.option("--movie", metavar="MOVIE.apng", callback=_not_empty,
              help="Also write the frames as an animated PNG (.apng) or GIF (.gif).")
@click.option("--skip-existing", is_flag=True, help="Leave the frames (or image) already written; render the rest.")
@_cluster_options
def render(scene_file, output, width, height, block_size, samples, max_depth, workers, tile,
           gamma, quiet, progress, stats, engine, no_bvh, frame_range, frame, movie, skip_existing,
           cluster, cluster_file, local_cluster):
    """Render SCENE.yaml to an image (see docs/scene-format.md for the scene format), or its frames."""
    from rtcli import frames as animation
    from rtcli.writer import write_png
    start = time.perf_counter()
    _check_engine(engine)
    where = _cluster(cluster, cluster_file, local_cluster)
    several = animation.wants_sequence(output, frame_range, movie)
    loaded = animation.load(scene_file, None if several else frame, keep=where is not None)
    scene, inputs, changes = loaded.scene, loaded.inputs, animation.overrides(samples, max_depth)
    if several:
        seq = animation.sequence(loaded.animation, scene_file, output, frame_range, frame, movie)
        outs = [(p, False) for p in seq.paths.values()] + [(m, "movie") for m in seq.movies]
    else:
        out = _output(scene_file, output)
        outs = [(out, False)]
    _check_outputs(outs, inputs)
    animation.apply(scene, changes)
    job = _job(scene, width, height, block_size, tile=tile, gamma=gamma, engine=engine, bvh=not no_bvh)
    show = _progress(not quiet and (progress or sys.stderr.isatty()), one_line(os.path.basename(scene_file)))
    if several:
        counts = animation.render_sequence(loaded, seq, job, workers or os.cpu_count() or 1, changes,
                                           skip_existing, show, where)
    elif skip_existing and os.path.isfile(out):
        return
    else:
        image, counts = animation.render_image(loaded, job, workers or os.cpu_count() or 1, show, where, changes)
        write_png(out, image)
    if stats:
        seconds = time.perf_counter() - start
        click.echo(f"rays: {counts.primary} primary, {counts.shadow} shadow, {counts.reflected} reflected, "
                   f"{counts.refracted} refracted, {counts.total} total; {counts.engine} engine; {seconds:.2f} s; "
                   f"{counts.total / max(seconds, 1e-9):,.0f} rays/s")


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
@_cluster_options
def signature(scene_file, output, ids_out, legend, width, height, block_size, workers, frame,
              cluster, cluster_file, local_cluster):
    """Write the scene signature: each pixel shows the id of the first object hit (notes 000 11.4)."""
    import numpy as np

    from rtcli.frames import load, render_image
    from rtcli.writer import signature_colors, write_images
    where = _cluster(cluster, cluster_file, local_cluster)
    loaded = load(scene_file, frame, keep=where is not None)
    scene, inputs = loaded.scene, loaded.inputs
    if len(scene.objects) > 65535:
        raise RtcliError(f"{shown(scene_file)}: {len(scene.objects)} objects, but signature ids are 16-bit "
                         "(at most 65535 objects)")
    out = _output(scene_file, output, ".sig.png")
    _check_outputs([(out, False)] + ([(ids_out, True)] if ids_out else []), inputs)
    job = _job(scene, width, height, block_size, signature=True)
    ids, _ = render_image(loaded, job, workers or os.cpu_count() or 1, where=where)
    write_images([(out, signature_colors(ids))] + ([(ids_out, ids)] if ids_out else []))
    if legend:
        counts = np.bincount(ids.ravel(), minlength=len(scene.objects) + 1)
        click.echo(f"{'id':>5}  {'name':<24} {'shape':<10} {'pixels':>9}")
        click.echo(f"{0:>5}  {'(background)':<24} {'-':<10} {counts[0]:>9}")
        for o in scene.objects:
            click.echo(f"{o.id:>5}  {one_line(o.name) or '-':<24} {o.kind:<10} {counts[o.id]:>9}")


@main.command()
@click.argument("actual", metavar="ACTUAL.png")
@click.argument("expected", metavar="EXPECTED.png")
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
def compare(actual, expected, diff, flip_out, ids_mode, tolerance, max_bad_pixels, max_bad_fraction,
            max_cluster, max_boundary_mismatch, max_boundary_fraction):
    """Compare two PNGs' pixels; exit 0 within tolerance, 1 beyond it."""
    from rtcli import compare as cmp
    from rtcli.writer import write_images
    _check_outputs([(p, False) for p in (diff, flip_out) if p], [actual, expected])
    a, e = cmp.read_png(actual), cmp.read_png(expected)
    id_options = dict(max_boundary_mismatch=max_boundary_mismatch, max_boundary_fraction=max_boundary_fraction)
    image_options = dict(tolerance=tolerance, max_bad_pixels=max_bad_pixels,
                         max_bad_fraction=max_bad_fraction, max_cluster=max_cluster)
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


@main.command()
@click.argument("scene_file", metavar="SCENE.yaml")
def validate(scene_file):
    """Parse and check a scene; print a summary. Renders nothing."""
    from rtcli.frames import load
    from rtcli.scenefile.build import summary
    loaded = load(scene_file)
    click.echo(f"{shown(scene_file)}: ok: {summary(loaded.scene)}{loaded.animation.check_all()}")


@main.command()
def presets():
    """List the material presets (McReynolds and Blythe) with their coefficients."""
    from rtcli.scenefile.presets import table_rows
    for row in table_rows():
        click.echo(row)
