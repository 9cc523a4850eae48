"""`rtcli validate` (README.md, Commands): a scene checked, every frame of an animated one, its
objects listed, and its warnings; and `rtcli presets`, the material presets."""

from __future__ import annotations

import click

from rtcli.errors import shown


@click.command()
@click.argument("scene_file", metavar="SCENE.yaml")
@click.option("--objects", "list_objects", is_flag=True,
              help="List every object: id, name, shape, material, shadow, triangles, world-space bounds.")
@click.option("--strict", is_flag=True, help="Warnings are errors (exit 2).")
def validate(scene_file, list_objects, strict):
    """Parse and check a scene, every frame of an animated one; print a summary, and warnings about
    likely mistakes on stderr. Renders only a small signature (does the camera see anything?)."""
    from rtcli.api.loading import load_file  # start-up
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


@click.command()
def presets():
    """List the material presets (McReynolds and Blythe) with their coefficients."""
    from rtcli.scenefile.presets import table_rows  # start-up
    for row in table_rows():
        click.echo(row)
