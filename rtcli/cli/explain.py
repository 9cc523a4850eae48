"""`rtcli explain SCENE X Y` (docs/debugging.md): why a pixel has its color, its ray tree with
every term of the shading equation, as text (colored on a terminal) or JSON."""

from __future__ import annotations

import os

import click

from rtcli.cli.options import SIZE, check_size, load


@click.command(context_settings={"ignore_unknown_options": True})       # a negative X or Y is a pixel, not an option
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
@click.option("--max-nodes", type=click.IntRange(1, 1_000_000), default=1000, show_default=True, metavar="N",
              help="Rays shown in full per sample's tree; the deeper ones are summarised.")
def explain(scene_file, x, y, width, height, samples, max_depth, sample, all_samples, as_json, gamma, no_bvh, frame,
            max_nodes):
    """Explain why pixel (X, Y) has its color: its ray tree, every term of the shading equation
    with its numbers, and the sum at every ray (X from the left, Y from the top, from 0)."""
    from rtcli.api import explain as explain_pixel  # start-up
    if sample is not None and all_samples:
        raise click.UsageError("--sample and --all-samples go one at a time")
    _, scene = load(scene_file, frame)
    check_size(scene.model, width, height)
    scene.override(width=width, height=height)
    e = explain_pixel(scene, x, y, samples=samples, max_depth=max_depth, gamma=gamma, bvh=not no_bvh,
                      max_nodes=max_nodes)
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
