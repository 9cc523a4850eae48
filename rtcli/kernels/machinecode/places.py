"""Which process may use a machine code file, and where the files are (rtcli/kernels/machinecode).

The switch (RTCLI_MACHINE_CODE), the key a description records (rtcli's sources and this
package's, the CPU, numba, llvmlite and Python), the folder beside numba's cache and the
description's name. Writing (writing.py) and loading (entries.py) read `ENABLED` and
`folder` from here, as module attributes, so both see the same switch and the same place.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import platform
import sys
from pathlib import Path

from rtcli.kernels import numba_cache

ENABLED = os.environ.get("RTCLI_MACHINE_CODE", "1") != "0"
SOURCES = numba_cache.COMPILED_DIRS      # what the machine code is made of: the folders numba compiles
PACKAGE = Path(numba_cache.PACKAGE_DIR)
HERE = Path(__file__).parent            # this package: any change to one of its files changes the key
ENTRY_SYMBOL = "rtcli_entry"            # the C function rtcli calls, the one symbol a description may name


def sources_digest(package: Path = PACKAGE, names: tuple = SOURCES) -> str:
    """SHA-256 of rtcli's sources that compiled code is made of (`names`, SOURCES by default, in
    `package`): each file's name and bytes, a folder's .py files in order of name."""
    digest = hashlib.sha256()
    for name in names:
        path = package / name
        for f in (sorted(path.glob("*.py")) if path.is_dir() else [path]):
            digest.update(f.name.encode() + f.read_bytes())
    return digest.hexdigest()


def key() -> dict:
    """This process as a machine code file cares: the description of a file it may use records
    the same."""
    return {"sources": _digest(), "cpu": cpu(), "numba": _version("numba"), "llvmlite": _version("llvmlite"),
            "python": sys.implementation.cache_tag, "platform": sys.platform}


def _version(package: str) -> str:
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return ""


def cpu(cpuinfo: str | None = None) -> str:
    """This CPU as machine code cares: a hash of its vendor, model and feature flags (Linux's
    /proc/cpuinfo, or `cpuinfo` given), else the platform module's description."""
    if cpuinfo is None:
        try:
            with open("/proc/cpuinfo") as f:
                cpuinfo = f.read()
        except OSError:
            cpuinfo = ""
    first = cpuinfo.split("\n\n")[0]
    fields = {k.strip(): v.strip() for k, _, v in (line.partition(":") for line in first.splitlines())}
    wanted = [fields.get(k, "") for k in ("vendor_id", "model name", "flags", "CPU implementer", "CPU part",
                                          "Features")]
    if any(wanted[1:]):
        return "cpuinfo " + hashlib.sha256("|".join(wanted).encode()).hexdigest()[:32]
    return f"{platform.machine()} {platform.processor()} {platform.platform()}"


_digests: list = []


def _digest() -> str:
    """The sources' digest and this package's (every .py file of it), once a process."""
    if not _digests:
        _digests.append(sources_digest() + sources_digest(HERE.parent, (HERE.name,))[:16])
    return _digests[0]


def folder() -> Path | None:
    """Where the files are: numba's cache folder of rtcli/compiled (numba_cache.cache_location), or None
    when there is no cache."""
    where = numba_cache.cache_location()
    return Path(where.folders()[numba_cache.COMPILED_DIRS.index("compiled")]) if where.enabled else None


def description_file(name: str, place: Path) -> Path:
    """The description of the entry `name`: its key, layout, symbol and library file."""
    return place / f"rtcli-{name}.json"
