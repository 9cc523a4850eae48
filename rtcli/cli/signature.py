"""`rtcli signature` (README.md, Commands; notes 000 11.4): each pixel the id of the first object
hit, as a color-coded picture, the raw ids as a 16-bit PNG, and the legend."""

from __future__ import annotations

import click

from rtcli.cli.options import SIZE, check_outputs, check_size, cluster_options, load, not_empty, output_name, reach
from rtcli.cli.terminal import note
from rtcli.errors import one_line


@click.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("-o", "--output", metavar="OUT.png", callback=not_empty,
              help="Color-coded signature (default: NAME.sig.png).")
@click.option("--ids", "ids_out", metavar="IDS.png", callback=not_empty,
              help="Also write the raw ids as a 16-bit gray PNG.")
@click.option("--legend", is_flag=True, help="Print id, name, shape and pixels covered.")
@click.option("--width", type=SIZE, help="Image width (the camera is kept).")
@click.option("--height", type=SIZE, help="Image height (the camera is kept).")
@click.option("--block-size", type=click.IntRange(1, 1024), default=1, show_default=True,
              help="One ray per N x N block, through its top-left pixel.")
@click.option("--workers", type=click.IntRange(1, 256), help="Worker processes (default: all cores).")
@click.option("--frame", type=click.IntRange(1), metavar="N", help="Frame N of an animated scene (default 1).")
@cluster_options()
def signature(scene_file, output, ids_out, legend, width, height, block_size, workers, frame,
              cluster, cluster_file, local_cluster):
    """Write the scene signature: each pixel shows the id of the first object hit (notes 000 11.4)."""
    import numpy as np  # start-up

    from rtcli import api
    from rtcli.api.pictures import check_ids
    from rtcli.api.pictures import legend as legend_rows
    from rtcli.cli.render_stills import on_cluster
    from rtcli.core.display import signature_colors
    from rtcli.rendering.writer import write_images
    where = reach(cluster, cluster_file, local_cluster, note)
    loaded, scene = load(scene_file, frame, keep=where is not None)
    out = output_name(scene_file, output, ".sig.png")
    check_outputs([(out, False)] + ([(ids_out, True)] if ids_out else []), scene.inputs)
    check_size(scene.model, width, height)
    if where is None:
        ids = api.signature(scene, width=width, height=height, block_size=block_size, workers=workers)
    else:
        check_ids(scene)
        with where:
            ids = on_cluster(loaded, scene, where, {}, width, height, block_size, signature=True)
    write_images([(out, signature_colors(ids), ids.meta)] + ([(ids_out, np.asarray(ids), ids.meta)] if ids_out else []))
    if legend:
        click.echo(f"{'id':>5}  {'name':<24} {'shape':<10} {'pixels':>9}")
        for row in legend_rows(scene, ids):
            click.echo(f"{row.id:>5}  {one_line(row.name) or '-':<24} {row.shape:<10} {row.pixels:>9}")
