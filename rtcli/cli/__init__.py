"""The rtcli command line (README.md, Commands): render, signature, explain, compare, info, validate,
preview, presets, warmup; one module a command, this one the group that wires them.

Argument handling only: each command parses its options and calls the library. Errors from the
library (RtcliError) and usage errors become one `error: ...` line on stderr with exit code 2;
`--debug` shows the traceback instead. Ctrl-C (SIGINT) and SIGTERM stop any command at once with
`error: interrupted` and exit code 130 or 143, leaving no file behind. The command modules import
the library inside their functions, so that `rtcli --help` and each command start quickly.
"""

from __future__ import annotations

import os
import signal
import sys
import threading

import click

from rtcli import __version__
from rtcli.cli.compare import compare
from rtcli.cli.explain import explain
from rtcli.cli.info import info
from rtcli.cli.preview import preview
from rtcli.cli.render import render
from rtcli.cli.signature import signature
from rtcli.cli.validate import presets, validate
from rtcli.cli.warmup import warmup
from rtcli.errors import Interrupted, RtcliError, error_line, one_line, shown


def _on_signal(signum, frame):
    raise Interrupted(signum)


class RtcliGroup(click.Group):
    """A click group whose errors are one line: 'error: ...', exit 2; no arguments shows the help."""

    def main(self, args=None, prog_name=None, **extra):
        # One BLAS thread: rtcli's parallelism is its worker processes, and OpenBLAS's idle threads
        # spin after each small matrix product of a scene's transforms, taking the workers' cores
        # (whitted at 1920x1080 on 2 cores: 13% more CPU). Set before numpy is first imported.
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
        args = list(sys.argv[1:] if args is None else args)
        extra.pop("standalone_mode", None)
        if not args:
            args = ["--help"]
        if (why := _nul_argument(args)) is not None:
            click.echo(f"error: {why}", err=True)
            sys.exit(2)
        restore = _catch_signals()
        try:
            code = super().main(args, prog_name or "rtcli", standalone_mode=False, **extra)
        except click.exceptions.Exit as e:
            sys.exit(e.exit_code)
        except (Interrupted, click.exceptions.Abort) as e:
            restore = _ignore_signals()                # the first signal decides; the exit is bounded
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
            click.echo(error_line(e), err=True)
            sys.exit(2)
        finally:
            restore()
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise Interrupted(signal.SIGINT) from None


def _nul_argument(args: list[str]) -> str | None:
    """The message for the first argument holding a NUL byte, named by its option (no path, and
    no other value rtcli takes, holds one; a shell cannot pass one, a program can), or None."""
    for k, arg in enumerate(args):
        if "\0" in arg:
            option, _, value = arg.partition("=") if arg.startswith("--") and "=" in arg else ("", "", arg)
            if not option and k and args[k - 1].startswith("-") and not arg.startswith("-"):
                option = args[k - 1]
            named = f"{shown(option)} " if option and "\0" not in option else ""
            return f"{named}{shown(value)}: an argument cannot hold a NUL byte (a path cannot)"
    return None


def _ignore_signals():
    """Ignore SIGINT and SIGTERM from now on (a process on its way out after the first: a later
    one, a supervisor's SIGTERM to the group, would otherwise kill it by the default action half
    way through its exit); returns the undo, which does nothing."""
    if threading.current_thread() is threading.main_thread():
        for s in (signal.SIGINT, signal.SIGTERM):
            signal.signal(s, signal.SIG_IGN)
    return lambda: None


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


for _command in (render, signature, explain, compare, info, validate, preview, presets, warmup):
    main.add_command(_command)
