"""Errors and warnings the library raises; cli.py turns errors into one-line messages (exit 2),
and IPython shows them as that one line too (RtcliError._render_traceback_)."""

from __future__ import annotations

import re
from dataclasses import dataclass

_PLAIN = re.compile(r"[\w./+@%,=:~-]+", re.ASCII)       # shown without quotes
_BYTE = re.compile(r"(?<!\\)((?:\\\\)*)\\udc([89a-f][0-9a-f])")   # repr's \udcXX: a byte that is not UTF-8
SOURCES = ("<string>", "<dict>")     # how scenes given to the Python API as YAML text or a dict are named


@dataclass(frozen=True, slots=True)
class Where:
    """A place in a scene file: 1-based line and column; line 0 for a scene given as a dict,
    which only its key path locates."""

    file: str
    line: int
    column: int

    def __str__(self) -> str:
        name = self.file if self.file in SOURCES else shown(self.file)
        return f"{name}:{self.line}:{self.column}" if self.line else name


def quoted(text) -> str:
    """Text from the user (a key, a name) in quotes, with every control or
    non-printable character escaped (Python's repr), so it stays on one line; a byte of
    a file name that is not UTF-8 (which Python holds as a lone surrogate) shows as \\xNN."""
    return _BYTE.sub(r"\1\\x\2", repr(str(text)))


def shown(text) -> str:
    """A path or a key as it appears in a message: as it is when it is plain
    (letters, digits and ./_-+@%,=:~), else quoted with escapes, so that a newline
    or a quote in it can neither break the message's line nor forge another."""
    text = str(text)
    return text if _PLAIN.fullmatch(text) else quoted(text)


def plural(n: int, word: str, words: str | None = None) -> str:
    """'1 warning', '2 warnings': a count with its noun (`words` when the plural is not word + s)."""
    return f"{n} {word if n == 1 else words or word + 's'}"


def one_line(message: str) -> str:
    """The message with any line break or other control character escaped: the last
    guard of the rule that every error is one line. A byte of a file name that is not
    UTF-8 shows as \\xNN, so the line can be written as UTF-8."""
    return "".join(c if c.isprintable() else _escaped(c) for c in message)


def _escaped(c: str) -> str:
    return f"\\x{ord(c) - 0xDC00:02x}" if "\udc80" <= c <= "\udcff" else repr(c)[1:-1]


def error_line(error: BaseException) -> str:
    """The line rtcli prints for an error (RtcliError, MemoryError): `error: ` and its message."""
    return f"error: {one_line(str(error) or 'out of memory')}"


class Interrupted(BaseException):
    """SIGINT or SIGTERM arrived: unwind (workers stopped, temporary files removed); exit 128 + signum."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


class RtcliError(Exception):
    """Any error meant for the user: bad input, unreadable file, bad option."""

    def _render_traceback_(self) -> list[str]:
        """What IPython and Jupyter show for this error instead of its traceback (IPython's
        convention): its one-line message, as the command line prints it (docs/python-api.md)."""
        return [f"{type(self).__name__}: {one_line(str(self))}"]


class RtcliWarning(UserWarning):
    """A likely mistake in a scene that is not an error (`rtcli validate`'s warnings), raised as a
    Python warning when the API loads the scene (docs/python-api.md)."""


class SceneError(RtcliError):
    """An error in a scene file: 'file:line:col: key.path: message'."""

    def __init__(self, where: Where | str | None, path: str, message: str):
        self.where, self.path, self.message = where, path, message
        parts = [str(where) if isinstance(where, Where) else shown(where)] if where else []
        if path:
            parts.append(path)
        parts.append(message)
        super().__init__(": ".join(parts))
