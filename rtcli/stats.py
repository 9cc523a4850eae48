"""Counts of rays traced, by kind, and the engine's start-up (for --stats)."""

from __future__ import annotations

from dataclasses import dataclass, fields


@dataclass
class Stats:
    primary: int = 0
    shadow: int = 0
    reflected: int = 0
    refracted: int = 0
    engine: str = ""                 # which engine traced them: "numpy" or "compiled"
    load_seconds: float = 0.0        # the engine's machine code loaded or compiled (rtcli.compiled.Load)
    compile_seconds: float = 0.0     # of which compiling

    def add(self, other: "Stats") -> None:
        for f in fields(self):
            if f.name not in ("engine", "load_seconds", "compile_seconds"):
                setattr(self, f.name, getattr(self, f.name) + getattr(other, f.name))

    @property
    def total(self) -> int:
        return self.primary + self.shadow + self.reflected + self.refracted
