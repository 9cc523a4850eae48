"""`rtcli compare` (README.md, Commands): two images through the golden gate, with a heat map and
FLIP's map; or two folders as a suite, with an HTML report and JUnit XML (rtcli/compare/). PNG,
EXR and PFM; a note when the two images were made with other settings or another rtcli."""

from __future__ import annotations

import click

from rtcli.cli.options import check_outputs, not_empty
from rtcli.errors import RtcliError


@click.command()
@click.argument("actual", metavar="ACTUAL.png|.exr|.pfm|ACTUAL_DIR")
@click.argument("expected", metavar="EXPECTED.png|.exr|.pfm|EXPECTED_DIR")
@click.option("--diff", metavar="DIFF.png", callback=not_empty, help="Write a heat map of the difference.")
@click.option("--flip", "flip_out", metavar="FLIP.png", callback=not_empty,
              help="Also write NVIDIA FLIP's perceptual error map and add its mean to the summary "
                   "(needs flip-evaluator: pip install -e '.[flip]' in the rtcli folder).")
@click.option("--ids", "ids_mode", is_flag=True, help="Compare signature id maps (16-bit gray PNGs, or the id "
                                                    "layers of two EXRs).")
@click.option("--tolerance", type=click.IntRange(0, 255), default=2, show_default=True,
              help="A pixel is bad when a channel differs by more than this (of 255).")
@click.option("--float-tolerance", type=click.FloatRange(0, min_open=True), default=0.01, show_default=True,
              help="EXR and PFM: a pixel is bad when a channel differs by more than this times max(1, expected), "
                   "in linear values.")
@click.option("--max-bad-pixels", type=click.IntRange(0), default=16, show_default=True,
              help="Bad pixels allowed: the larger of this and --max-bad-fraction of the image.")
@click.option("--max-bad-fraction", type=click.FloatRange(0, 1), default=1e-4, show_default=True)
@click.option("--max-cluster", type=click.IntRange(0), default=3, show_default=True,
              help="Largest allowed 8-connected cluster of bad pixels.")
@click.option("--max-boundary-mismatch", type=click.IntRange(0), default=8, show_default=True,
              help="--ids: mismatches allowed on id boundaries (or the fraction below, if larger).")
@click.option("--max-boundary-fraction", type=click.FloatRange(0, 1), default=0.01, show_default=True)
@click.option("--report", "report_dir", metavar="DIR", callback=not_empty,
              help="Folders: write an HTML report there (index.html and its pictures), worst pair first.")
@click.option("--junit", "junit_file", metavar="FILE", callback=not_empty,
              help="Folders: write the results as JUnit XML, one test case per pair.")
def compare(actual, expected, diff, flip_out, ids_mode, tolerance, float_tolerance, max_bad_pixels, max_bad_fraction,
            max_cluster, max_boundary_mismatch, max_boundary_fraction, report_dir, junit_file):
    """Compare two images' pixels (PNG, EXR or PFM); exit 0 within tolerance, 1 beyond it.

    Given two folders, compare every .png, .exr and .pfm in them paired by relative path: exit 0
    when every pair passes, 1 when one fails or is missing or extra.
    """
    id_options = dict(max_boundary_mismatch=max_boundary_mismatch, max_boundary_fraction=max_boundary_fraction)
    image_options = dict(tolerance=tolerance, float_tolerance=float_tolerance, max_bad_pixels=max_bad_pixels,
                         max_bad_fraction=max_bad_fraction, max_cluster=max_cluster)
    if _folders(actual, expected, diff or flip_out or ids_mode, report_dir or junit_file):
        from rtcli.compare.suite import compare_dirs  # start-up
        if not compare_dirs(actual, expected, image_options, id_options, report_dir, junit_file, click.echo):
            raise click.exceptions.Exit(1)
        return
    check_outputs([(p, False) for p in (diff, flip_out) if p], [actual, expected])
    _two_images(actual, expected, diff, flip_out, ids_mode, image_options, id_options)


def _two_images(actual, expected, diff, flip_out, ids_mode, image_options: dict, id_options: dict) -> None:
    from rtcli.compare import floats  # start-up
    from rtcli.compare import images as cmp
    from rtcli.rendering.provenance import differences
    from rtcli.rendering.writer import write_images
    a, e = floats.read_image(actual), floats.read_image(expected)
    notes = differences(a.meta, e.meta)
    if ids_mode and (a.ids is not None or e.ids is not None):
        a, e = (a.ids if a.ids is not None else a), (e.ids if e.ids is not None else e)      # EXRs' id layers
    if ids_mode:
        result = cmp.compare_ids(a, e, **id_options)
    else:
        result = floats.compare_any(a, e, image_options, id_options)
    summary = result.summary
    comparable = a.shape[:2] == e.shape[:2] and a.ndim == e.ndim == 3 and a.dtype.kind == e.dtype.kind
    if flip_out and comparable and a.dtype.kind == "f":
        raise RtcliError("--flip compares 8-bit pictures; EXR and PFM are compared in linear floats")
    pictures = []
    if diff and comparable:
        tolerance = image_options.get("float_tolerance", floats.FLOAT_TOLERANCE)
        pictures.append((diff, floats.heat_map_floats(a, e, tolerance) if a.dtype.kind == "f"
                         else cmp.heat_map(a, e, image_options["tolerance"])))
    if flip_out and comparable:
        picture, mean = cmp.flip_map(a, e)
        pictures.append((flip_out, picture))
        summary += f", mean FLIP {mean:.4f}"
    write_images(pictures)
    click.echo(summary)
    for note in notes:
        click.echo(note)
    if not result.ok:
        raise click.exceptions.Exit(1)


def _folders(actual: str, expected: str, pair_options, folder_options) -> bool:
    """Whether compare is given two folders; a usage error for a folder and a file, or for options
    of the other mode."""
    from rtcli.compare.suite import are_folders  # start-up
    folders = are_folders(actual, expected)
    if folders and pair_options:
        raise click.UsageError("--diff, --flip and --ids compare two images; two folders get --report")
    if not folders and folder_options:
        raise click.UsageError("--report and --junit compare two folders")
    return folders
