"""What the command line prints on stderr besides errors: the progress bar, notes (from any
thread: a cluster's workers speak while the bar runs), the scene's warnings, and the watch's
lines after the time of day."""

from __future__ import annotations

import threading
import time

import click

from rtcli.cli.options import check_size


def size(model, width, height) -> tuple[int, int]:
    """The image size of a scene's model (options.check_size), its note printed."""
    w, h, note = check_size(model, width, height)
    if note:
        click.echo(f"note: {note}", err=True)
    return w, h


_terminal = threading.Lock()          # the progress bar and the notes share stderr's last line


_bar_open = [False]                   # a progress bar's line is on stderr, not ended yet


def progress_bar(enabled: bool, label: str):
    if not enabled:
        return None

    def show(done, total):
        bar = "#" * (30 * done // total)
        with _terminal:
            click.echo(f"\r{label} [{bar:<30}] {100 * done // total:3d}%", err=True, nl=done == total)
            _bar_open[0] = done != total
    return show


def note(text: str) -> None:
    """A `note:` line on stderr, from any thread (a cluster's workers speak while the render runs):
    below a progress bar's unfinished line, the bar going on on the next line."""
    with _terminal:
        click.echo(("\n" if _bar_open[0] else "") + f"note: {text}", err=True)
        _bar_open[0] = False


def lint(quiet: bool, strict: bool, several: bool, watch: bool):
    """What render does with a scene's warnings (lint.Lint): printed on stderr (after the time
    in a watch, as its other lines), hidden by --quiet, errors with --strict."""
    from rtcli.inspect.lint import Lint  # start-up
    return Lint(stamped if watch else echo_err, quiet, strict, several)


def echo_err(line: str) -> None:
    click.echo(line, err=True)


def stamped(line: str) -> None:
    """A watch's line on stderr, after the time of day, as its renders' lines."""
    click.echo(f"{clock()} {line}", err=True)


def clock() -> str:
    """The time of day, HH:MM:SS, that begins a watch's lines."""
    return time.strftime("%H:%M:%S")
