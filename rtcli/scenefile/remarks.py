"""What loading a scene remembers for `rtcli validate` (README.md, `validate`): where the camera
and each light are written, and values that load but look like
mistakes (colors written as 0-255 values).

Loading records them only inside `recording_remarks()`, as files.py records inputs, so a
render pays nothing for them.
"""

from __future__ import annotations

import contextlib
import contextvars
from dataclasses import dataclass, field

from rtcli.errors import Where


@dataclass(frozen=True)
class Remark:
    """A warning about a scene: where (as 'file:line:col: key.path') and what."""

    where: str
    message: str

    def __str__(self) -> str:
        return f"{self.where}: warning: {self.message}"


@dataclass
class Remarks:
    """What one load recorded."""

    camera: str = ""                                     # where `camera:` is written
    lights: list[str] = field(default_factory=list)      # where each light is written, in order
    lights_key: str = ""                                 # where `lights:` is, or would go
    objects_key: str = ""                                # where `objects:` is, or would go
    colors: list[Remark] = field(default_factory=list)   # colors that look like 0-255 values


_current: contextvars.ContextVar[Remarks | None] = contextvars.ContextVar("rtcli_remarks", default=None)


@contextlib.contextmanager
def recording_remarks():
    """Remarks of every scene loaded inside the block (the last load's, when several are)."""
    remarks = Remarks()
    token = _current.set(remarks)
    try:
        yield remarks
    finally:
        _current.reset(token)


def current() -> Remarks | None:
    """The Remarks being recorded, or None when nobody asked for them."""
    return _current.get()


def at(where: Where | str, path: str) -> str:
    """'file:line:col: key.path', the place a remark names."""
    return f"{where}: {path}" if path else str(where)


def note_color(value, where: Where, label: str) -> None:
    """Record a color whose channels look like 0-255 values: every channel above 1 written as a
    whole number (255, not 255.0), each at most 255. Such a color is probably a byte color;
    rtcli's colors run from 0 to 1. A decimal point says that more than 1 is meant."""
    remarks = _current.get()
    if remarks is None:
        return
    channels = list(value) if isinstance(value, list) else [value] * 3
    above = [c for c in channels if c > 1]
    if not above or not all(isinstance(c, int) and not isinstance(c, bool) and c <= 255 for c in above):
        return
    written = f"[{', '.join(map(str, channels))}]" if isinstance(value, list) else str(value)
    scaled = ", ".join(f"{c / 255:.3g}" for c in channels)
    hex_form = "#" + "".join(f"{round(c):02x}" for c in channels)
    remarks.colors.append(Remark(at(where, label), (
        f"{written} looks like 0-255 values, but colors run from 0 to 1 here: [{scaled}] or "
        f"\"{hex_form}\" (write {above[0]}.0 if more than 1 is meant)")))
