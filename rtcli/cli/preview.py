"""`rtcli preview` (docs/preview.md): the scene in the browser as it renders, coarse to fine,
rendered again at every save, a pixel explained on a click (rtcli/preview/)."""

from __future__ import annotations

import click

from rtcli.cli.options import SIZE, not_empty


@click.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("--port", type=click.IntRange(0, 65535), default=0, show_default=True,
              help="The port to serve on (0: any free one).")
@click.option("--host", default="127.0.0.1", show_default=True, callback=not_empty,
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
@click.option("--against", metavar="GOLDEN.png", callback=not_empty,
              help="Compare each finished render with this image: heat map, slider, FLIP where installed.")
@click.option("--tev", metavar="HOST:PORT", callback=not_empty,
              help="Also stream the tiles and views to the tev viewer listening there (its default: 127.0.0.1:14158).")
def preview(scene_file, port, host, no_browser, width, height, samples, max_depth, engine, gamma, no_bvh, workers,
            frame, against, tev):
    """Serve a live preview of SCENE.yaml in the browser: it renders coarse to fine, renders again at
    every save of the scene or a file it reads, and explains the pixel clicked. Ctrl-C ends it
    (docs/preview.md). Needs the extra `preview`: pip install -e '.[preview]' in the rtcli folder."""
    from rtcli.api.options import check_engine  # start-up
    from rtcli.cli.terminal import stamped
    from rtcli.preview import Options, serve
    check_engine(engine)
    options = Options(width, height, samples, max_depth, engine, gamma, not no_bvh, frame, workers)
    serve(scene_file, options, host=host, port=port, browser=not no_browser, against=against, tev=tev,
          url=lambda text: click.echo(text), say=stamped)
