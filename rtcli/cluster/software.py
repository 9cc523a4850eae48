"""The same software everywhere: what a worker's pixels depend on besides the scene, compared
with the client's when it connects and again in every task (for workers that join later)."""

from __future__ import annotations

import sys

from rtcli import __version__
from rtcli.errors import RtcliError
from rtcli.rendering.provenance import sources_digest

LIBRARIES = ("numpy", "numba", "llvmlite", "PIL", "yaml")


# --- the same software everywhere ---
_fingerprint: dict | None = None


def fingerprint() -> dict:
    """What the pixels depend on besides the scene: rtcli's version and sources, Python's and the
    libraries' versions (numba's too: it decides the engine)."""
    global _fingerprint
    if _fingerprint is None:
        found = {"rtcli": f"{__version__} (sources {sources_digest()[:12]})",
                 "python": ".".join(map(str, sys.version_info[:3]))}
        for name in LIBRARIES:
            try:
                found[name] = __import__(name).__version__
            except ImportError:
                found[name] = "not installed"
        _fingerprint = found
    return _fingerprint


def mismatch(client: dict, worker: dict, where: str) -> RtcliError | None:
    """The refusal when a worker's fingerprint differs from the client's, or None."""
    differ = [f"{name} {client.get(name)} here, {worker.get(name)} there"
              for name in sorted(set(client) | set(worker)) if client.get(name) != worker.get(name)]
    if not differ:
        return None
    return RtcliError(f"the worker {where} runs other software ({'; '.join(differ)}): its pixels could differ; "
                      "install the same rtcli and libraries on every worker")
