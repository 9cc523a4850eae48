"""What several commands share: option types and checks, the cluster options, a scene file
loaded with the command line's overrides, and output names and checks.

The library is imported inside the functions that need it (start-up: `rtcli --help` and the
commands' option parsing load no numpy).
"""

from __future__ import annotations

import os

import click

SIZE = click.IntRange(1, 32768)
VIEWS = ("normal", "depth", "uv", "albedo", "bounces", "ids")          # rtcli/inspect/views.py, not imported to start


def not_empty(ctx, param, value):
    if value is not None and not value.strip():
        raise click.BadParameter("must not be empty", ctx, param)
    return value


def layer_list(ctx, param, value):
    """--layers: a comma-separated list of view kinds, each once, as a tuple."""
    if value is None:
        return ()
    kinds = tuple(dict.fromkeys(k.strip() for k in value.split(",")))
    unknown = [k for k in kinds if k not in VIEWS]
    if unknown:
        raise click.BadParameter(f"no layer {', '.join(map(repr, unknown))}: layers are {', '.join(VIEWS)}",
                                 ctx, param)
    return kinds


def output_name(scene_path: str, out: str | None, suffix: str = ".png") -> str:
    """-o as given, or the scene's name with `suffix`, here."""
    return out or os.path.splitext(os.path.basename(scene_path))[0] + suffix


def check_outputs(outputs, inputs) -> None:
    from rtcli.rendering.outputs import check_outputs as check  # start-up
    check(outputs, inputs)


def load(path: str, frame: int | None = None, keep: bool = False, lint=None, **overrides):
    """(api.loading.Loaded, api.Scene) of a scene file at frame `frame` (default 1), with the
    command line's overrides; `keep`: also the files' bytes, for a cluster; `lint`
    (inspect.lint.Lint): what to do with its warnings."""
    from rtcli.api.loading import load_file, of_loaded  # start-up
    loaded = load_file(path, frame, keep=keep, lint=lint is not None and lint.wanted)
    if lint is not None:
        lint.report(loaded.warnings, path, loaded.animation.frames)
    return loaded, of_loaded(loaded, path).override(**overrides)


def check_size(model, width, height) -> tuple[int, int, str | None]:
    """api.options.image_size, its errors naming the options --width and --height."""
    from rtcli.api.options import image_size  # start-up
    return image_size(model, width, height, ("--width", "--height"))


def cluster_options(doing: str = "Render on", extra: str = " --workers is then unused."):
    """--cluster, --cluster-file and --local-cluster (README.md, Clusters), their help saying what
    the command does there."""
    def add(command):
        for option in reversed((
                click.option("--cluster", metavar="tcp://HOST:PORT", callback=not_empty,
                             help=f"{doing} the Dask cluster whose scheduler listens there (needs the extra "
                                  f"`cluster`).{extra}"),
                click.option("--cluster-file", metavar="SCHEDULER.json", callback=not_empty,
                             help=f"{doing} the Dask cluster named by this scheduler file."),
                click.option("--local-cluster", type=click.IntRange(1, 256), metavar="N",
                             help=f"{doing} a Dask cluster of N worker processes started on this machine."))):
            command = option(command)
        return command
    return add


def reach(address, file, local, notes):
    """The cluster the options name (a cluster.renders.Reach, to use in a `with` block), or None;
    rtcli.cluster (and Dask) only when one is named. The workers' notes go to `notes`
    (terminal.note: stderr, above the progress bar)."""
    if not (address or file or local):
        return None
    from rtcli.cluster.renders import Reach  # start-up: Dask only when asked
    from rtcli.cluster.target import target
    return Reach(target(address, file, local), notes)
