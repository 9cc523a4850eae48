"""Errors the library raises; cli.py turns them into one-line messages (exit 2)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Where:
    """A place in a scene file: 1-based line and column."""

    file: str
    line: int
    column: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


class RtcliError(Exception):
    """Any error meant for the user: bad input, unreadable file, bad option."""


class SceneError(RtcliError):
    """An error in a scene file: 'file:line:col: key.path: message'."""

    def __init__(self, where: Where | str | None, path: str, message: str):
        self.where, self.path, self.message = where, path, message
        parts = [str(where)] if where else []
        if path:
            parts.append(path)
        parts.append(message)
        super().__init__(": ".join(parts))
