"""Where numba keeps the machine code it compiles for rtcli (its on-disk cache): beside the
sources when they are writable, else RTCLI_CACHE_DIR, NUMBA_CACHE_DIR or the per-user cache, in
folders made private to the user (docs/architecture.md, Trust in the machine code files)."""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import sys
import tempfile

CACHE_ENV = "RTCLI_CACHE_DIR"
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # rtcli/, as numba sees it (not resolved)
COMPILED_DIRS = ("kernels", "core", "shapes", "compiled")    # rtcli's folders whose functions numba compiles


class CacheLocation:
    """Where numba keeps rtcli's machine code: beside the sources (numba's default, each folder's
    __pycache__) when they are writable, else a folder of its own (`root`, numba's NUMBA_CACHE_DIR:
    under it a folder per source folder, named by numba after the folder's path), or nowhere."""

    def __init__(self, root: str | None, why: str, enabled: bool = True):
        self.root, self.why, self.enabled = root, why, enabled

    def folders(self) -> list[str]:
        """The folders numba writes rtcli's cache files to, one per folder of sources."""
        dirs = [os.path.join(PACKAGE_DIR, d) if d else PACKAGE_DIR for d in COMPILED_DIRS]
        if self.root is None:
            return [os.path.join(d, "__pycache__") for d in dirs]
        return [os.path.join(self.root, numba_subfolder(d)) for d in dirs]

    def __str__(self) -> str:
        if not self.enabled:
            return "nowhere"
        return os.path.join(PACKAGE_DIR, "*", "__pycache__") if self.root is None else self.root

    @contextlib.contextmanager
    def applied(self):
        """numba's cache folder set to this one while rtcli's functions are made (numba's cache of
        a function is placed when the function is made), and restored after: other numba users of
        the process keep theirs."""
        from numba.core import config  # numba, optional (the fast extra): only when compiling
        saved = config.CACHE_DIR
        config.CACHE_DIR = self.root or ""
        try:
            yield
        finally:
            config.CACHE_DIR = saved


def numba_subfolder(source_dir: str) -> str:
    """The folder numba keeps a source folder's cache in, under a cache root (numba's
    _CacheLocator.get_suitable_cache_subpath): the folder's name and the SHA-1 of its path."""
    path = os.path.abspath(source_dir)
    return os.path.basename(path) + "_" + hashlib.sha1(path.encode()).hexdigest()


def user_cache_base() -> str:
    """The platform's per-user cache folder (~/.cache, or XDG_CACHE_HOME, on Linux)."""
    if os.name == "nt":
        return os.environ.get("LOCALAPPDATA") or os.path.expanduser(os.path.join("~", "AppData", "Local"))
    if sys.platform == "darwin":
        return os.path.expanduser("~/Library/Caches")
    return os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")


def user_cache_dir() -> str:
    """rtcli's per-user cache of machine code: ~/.cache/rtcli/numba on Linux."""
    return os.path.join(user_cache_base(), "rtcli", "numba")


def writable(folder: str) -> bool:
    """Whether files can be made in `folder` (made if missing): numba's own test of a cache folder."""
    try:
        make_private(folder)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def make_private(folder: str) -> None:
    """Make `folder` and each missing folder above it with mode 0700: only this user may read or
    change what rtcli caches there (docs/architecture.md, Trust in the machine code files)."""
    missing, path = [], os.path.abspath(folder)
    while not os.path.isdir(path) and os.path.dirname(path) != path:
        missing.append(path)
        path = os.path.dirname(path)
    for path in reversed(missing):
        os.makedirs(path, mode=0o700, exist_ok=True)


@functools.lru_cache(maxsize=None)
def cache_location() -> CacheLocation:
    """Where rtcli's machine code is cached, the first of: RTCLI_CACHE_DIR; NUMBA_CACHE_DIR; beside
    the sources when all their folders are writable (numba's default); the per-user cache
    (user_cache_dir(), for a read-only install); nowhere (each run compiles) when none is writable.
    Decided once, when the first compiled function is made; it only applies to rtcli's functions."""
    for name in (CACHE_ENV, "NUMBA_CACHE_DIR"):
        root = os.environ.get(name)
        if root:
            root = os.path.abspath(os.path.expanduser(root))
            return _private_location(CacheLocation(root, name)) if writable(root) else CacheLocation(
                root, f"{name} is not writable", False)
    beside = CacheLocation(None, "beside the sources")
    if all(writable(f) for f in beside.folders()):
        return beside
    root = user_cache_dir()
    if writable(root):
        return _private_location(CacheLocation(root, "the per-user cache: rtcli's folder is read-only"))
    return CacheLocation(None, "no writable folder: rtcli's is read-only and so is " + root, False)


def _private_location(location: CacheLocation) -> CacheLocation:
    """`location`, its folders made by rtcli (mode 0700) before numba makes them (with the umask's)."""
    for folder in location.folders():
        try:
            make_private(folder)
        except OSError:
            pass                        # numba says so when it cannot write there
    return location

