"""`rtcli render` (README.md, Commands): its options, the combinations it refuses, and which run
takes them: an animation's frames (render_frames.py), or one scene or many, each to an image,
once or at every save (render_stills.py)."""

from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass

import click

from rtcli.cli.options import SIZE, VIEWS, cluster_options, layer_list, not_empty, reach


@dataclass(frozen=True)
class Options:
    """`rtcli render`'s options, as click parses them."""

    scene_files: tuple
    output: str | None
    width: int | None
    height: int | None
    block_size: int
    samples: int | None
    max_depth: int | None
    workers: int | None
    tile: int
    gamma: bool
    quiet: bool
    progress: bool
    stats: bool
    as_json: bool
    engine: str
    no_bvh: bool
    view: str | None
    frame_range: str | None
    frame: int | None
    movie: str | None
    skip_existing: bool
    strict: bool
    keep_going: bool
    cluster: str | None
    cluster_file: str | None
    local_cluster: int | None
    watch: bool
    bit_depth: str = "8"
    half: bool = False
    alpha: bool = False
    layers: tuple = ()

    @property
    def several(self) -> bool:
        """Several scenes, or a folder of them."""
        return len(self.scene_files) > 1 or os.path.isdir(self.scene_files[0])

    @property
    def sequence(self) -> bool:
        """Frames to files or a movie, rather than one image a scene."""
        from rtcli.rendering.frames import wants_sequence  # start-up
        return wants_sequence(self.output, self.frame_range, self.movie)

    @property
    def on_cluster(self) -> bool:
        return bool(self.cluster or self.cluster_file or self.local_cluster)

    @property
    def bar(self) -> bool:
        """Whether a progress bar shows: on a terminal, or asked for, unless --quiet."""
        return not self.quiet and (self.progress or sys.stderr.isatty())

    @property
    def write(self) -> dict:
        """How the images are written (ImageArray.stage's options)."""
        return {"bit_depth": int(self.bit_depth), "half": self.half, "gamma": self.gamma}

    @property
    def changes(self) -> dict:
        """The render settings the options change."""
        return {name: v for name, v in (("samples", self.samples), ("max_depth", self.max_depth)) if v}


def refused(o: Options) -> str | None:
    """Why the options cannot go together (a usage error), or None."""
    from rtcli.rendering.movie import is_movie  # start-up
    sequence, several = o.sequence, o.several
    return next((why for bad, why in [
        (o.as_json and not o.stats, "--json goes with --stats"),
        (o.view and o.stats, "--stats counts the rays of a render, not of a --view"),
        (o.view and (o.layers or o.half or o.bit_depth != "8" or o.alpha),
         "--view writes an 8-bit picture: --layers, --half, --bit-depth and --alpha are for the render"),
        (sequence and (o.layers or o.half or o.bit_depth != "8" or o.alpha),
         "--layers, --half, --bit-depth and --alpha write still images, not frames or movies"),
        (several and (o.frame_range or o.movie or is_movie(o.output)),
         "--frames and movies render one animated scene, not several (--frame N renders frame N of each)"),
        (o.view and sequence and not several,
         "--view writes one picture: give --frame N, not --frames, a frame pattern or a movie"),
        (o.view and o.on_cluster, "--view is computed on this machine: it takes no cluster option"),
        (o.watch and several, "--watch renders one scene file"),
        (o.watch and (sequence or o.skip_existing), "--watch renders one image at every change: give --frame N, "
                                                    "not --frames, a frame pattern, a movie or --skip-existing"),
        (o.watch and o.on_cluster, "--watch renders on this machine: it takes no cluster option"),
        (o.keep_going and (o.watch or sequence), "--keep-going renders the other scenes when one is broken: it "
                                                 "takes no --watch, --frames, frame pattern or movie"),
    ] if bad), None)


@click.command()
@click.argument("scene_files", metavar="SCENE.yaml...", nargs=-1, required=True)
@click.option("-o", "--output", metavar="OUT.png|DIR", callback=not_empty,
              help="Output image (default: the scene's name .png); the format follows the extension: "
                   ".png, .jpg, .bmp, .tif, .webp or .ppm, or .exr and .pfm for the linear radiance as floats. Frames: a name with the frame number as %d "
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
@click.option("--bit-depth", type=click.Choice(["8", "16"]), default="8", show_default=True,
              help="Bits per channel of a PNG or TIFF: 16 keeps the linear radiance's precision.")
@click.option("--half", is_flag=True, help="An EXR's floats as float16 (default float32).")
@click.option("--alpha", is_flag=True, help="The background transparent (as the scene's render: {alpha: true}): "
                                            "PNG, TIFF, WebP or EXR.")
@click.option("--layers", metavar="KIND,...", callback=layer_list,
              help="Views to write as layers of the EXR beside the color: normal, depth, uv, albedo, bounces, "
                   "ids (one ray a pixel; README.md, Images).")
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
@click.option("--movie", metavar="MOVIE.apng", callback=not_empty,
              help="Also write the frames as an animated PNG (.apng) or GIF (.gif).")
@click.option("--skip-existing", is_flag=True, help="Leave the frames (or images) already written at the size "
                                                    "asked for; render the rest.")
@click.option("--strict", is_flag=True, help="The scene's warnings (as validate prints them) are errors (exit 2).")
@click.option("--keep-going", is_flag=True, help="Several scenes or a folder: when one is broken, print its error, "
                                                 "render the others, and exit 2 at the end.")
@cluster_options()
@click.option("--watch", is_flag=True, help="Render again whenever the scene or a file it reads changes; "
                                            "print each render's time; Ctrl-C ends.")
def render(**options):
    """Render SCENE.yaml to an image (see docs/scene-format.md for the scene format), or its frames;
    several scenes, or a folder of them, to a folder of images."""
    from rtcli.api.options import check_engine  # start-up: the library, once the options parse
    from rtcli.cli import render_frames, render_stills, terminal
    from rtcli.kernels import machinecode
    o = Options(**options)
    if (why := refused(o)) is not None:
        raise click.UsageError(why)
    check_engine(o.engine)
    if o.stats:                     # why a machine code file is not used, if one is not
        machinecode.report_to(terminal.note)
    where = reach(o.cluster, o.cluster_file, o.local_cluster, terminal.note)
    lint = terminal.lint(o.quiet, o.strict, o.several, o.watch)
    with where or contextlib.nullcontext():
        if o.sequence and not o.several:
            return render_frames.run(o, where, lint)
        broken = render_stills.run(o, where, lint)
    if broken:
        raise click.exceptions.Exit(2)
