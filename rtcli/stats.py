"""Counts of rays traced, by kind (for --stats)."""

from __future__ import annotations

from dataclasses import dataclass, fields


@dataclass
class Stats:
    primary: int = 0
    shadow: int = 0
    reflected: int = 0
    refracted: int = 0
    engine: str = ""                 # which engine traced them: "numpy" or "compiled"

    def add(self, other: "Stats") -> None:
        for f in fields(self):
            if f.name != "engine":
                setattr(self, f.name, getattr(self, f.name) + getattr(other, f.name))

    @property
    def total(self) -> int:
        return self.primary + self.shadow + self.reflected + self.refracted
