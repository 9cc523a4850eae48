"""`rtcli info IMAGE...` (README.md, Images): what an image says about how it was made, its
provenance (rtcli version and sources, the scene file and its SHA-256, the settings, the
engine and the render's time), with its format, size and channels."""

from __future__ import annotations

import click


@click.command()
@click.argument("images", metavar="IMAGE...", nargs=-1, required=True)
@click.option("--json", "as_json", is_flag=True, help="One JSON object per image, one a line.")
def info(images, as_json):
    """Print how each IMAGE was made (the provenance rtcli writes into PNG, TIFF, JPEG, WebP and EXR
    files), and its format, size and channels. Exit 1 when an image carries no provenance."""
    import json  # start-up

    from rtcli.rendering.provenance import PREFIX, lines
    from rtcli.rendering.reading import about
    found = [(path, about(path)) for path in images]              # every file read before anything prints
    for k, (path, a) in enumerate(found):
        if as_json:
            click.echo(json.dumps({"image": path, "format": a.format, "width": a.width, "height": a.height,
                                   "channels": a.channels, **{k[len(PREFIX):]: v for k, v in a.meta.items()}}))
            continue
        if len(found) > 1:
            click.echo(("\n" if k else "") + f"{path}:")
        click.echo(f"{'file':<14}  {a.format} {a.width}x{a.height}, channels {a.channels}")
        for line in lines(a.meta) or ["(no rtcli provenance: written by another program, or a format without "
                                      "room for it: BMP, PPM, PFM)"]:
            click.echo(line)
    if any(not a.meta for _, a in found):
        raise click.exceptions.Exit(1)
