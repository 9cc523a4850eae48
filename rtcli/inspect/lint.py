"""Warnings where users look (README.md, `render`): the warnings of `rtcli validate` (checks.py)
about the scene a render, a watch or the Python API loads.

Loading asked for them records where things are written (scenefile/remarks.py), and
checks.warnings looks at frame 1, as `validate` does. The command line prints each on
stderr, one line in validate's located form, before anything is traced; `--quiet` hides
them, `--strict` makes the first an error. The Python API raises them as Python warnings
(rtcli.RtcliWarning, a UserWarning) when it loads a scene, so notebooks show them.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass

from rtcli.errors import RtcliWarning, one_line, shown
from rtcli.inspect import checks
from rtcli.scenefile.remarks import Remark


@dataclass(frozen=True)
class Lint:
    """What a command does with a scene's warnings."""

    echo: Callable[[str], None]            # prints one line on stderr
    quiet: bool = False                    # hide them
    strict: bool = False                   # the first is an error (exit 2, no image)
    several: bool = False                  # one of several scenes: a warning in an include names its scene

    @property
    def wanted(self) -> bool:
        """Whether loading should look for warnings at all (hidden ones cost nothing)."""
        return self.strict or not self.quiet

    def report(self, found: list[Remark], scene_file: str, frames: int) -> None:
        """Print the warnings, or raise the first with --strict."""
        if self.strict and found:
            raise checks.strict_error(found)
        if not self.quiet:
            for line in lines(found, scene_file, frames, self.several):
                self.echo(line)


def lines(found: list[Remark], scene_file: str, frames: int, several: bool = False) -> list[str]:
    """One line per warning, `file:line:col: key.path: warning: ...`; with `several`, one located
    in another file (an include) ends with the scene that includes it. Then, for an animated
    scene, a note that they are about frame 1."""
    own = shown(scene_file) + ":"
    out = [one_line(str(r)) + ("" if not several or r.where.startswith(own) else f" (included by {own[:-1]})")
           for r in found]
    if found and frames > 1:
        out.append(f"note: the warnings are about frame 1 of {frames} (the camera, lights and objects where "
                   "the animation starts)")
    return out


def warn(found: list[Remark]) -> None:
    """Each warning as a Python RtcliWarning, attributed to the first caller outside rtcli (the
    notebook cell or script line that loaded the scene). Every load warns again, as every render
    does: Python's default filter would show a warning once per line, and a cell run again after
    an edit elsewhere would then hide it."""
    frame = _outside_rtcli(sys._getframe(1))
    for remark in found:
        warnings.warn_explicit(RtcliWarning(one_line(f"{remark.where}: {remark.message}")), RtcliWarning,
                               frame.f_code.co_filename, frame.f_lineno, frame.f_globals.get("__name__", ""),
                               registry=None, module_globals=frame.f_globals)


def _outside_rtcli(frame):
    """The first frame from `frame` outward whose code is not rtcli's (`frame` itself if all are)."""
    first = frame
    while frame is not None and frame.f_globals.get("__name__", "").partition(".")[0] == "rtcli":
        frame = frame.f_back
    return frame or first
