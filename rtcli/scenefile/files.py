"""Opening the files a scene names: scene files, includes, meshes and textures.

Every input is checked with os.stat before it is opened: only regular files are
read (opening a FIFO would block, and a device such as /dev/zero never ends), and
files larger than their documented limit (docs/scene-format.md, "Limits") are
refused without being read. The real paths of the files a load reads are
recorded, so the command line can refuse an output that would overwrite one, and
so are their stamps as read, so `rtcli render --watch` sees them change.

A load can also keep the bytes of every file it reads (`collecting`), and another
load, in another process or on another machine, can read those bytes instead of
the disk (`serving`): a render spread over a cluster sends its workers the scene
as the files the client read, so that every worker builds the same scene.
"""

from __future__ import annotations

import contextlib
import contextvars
import gc
import io
import os
import stat
import warnings

from PIL import Image

from rtcli.scenefile.limits import MAX_IMAGE_BYTES, MAX_TEXTURE_PIXELS, MB

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))

_read: contextvars.ContextVar[list | None] = contextvars.ContextVar("rtcli_inputs", default=None)
_kept: contextvars.ContextVar[dict | None] = contextvars.ContextVar("rtcli_kept_files", default=None)
_served: contextvars.ContextVar[dict | None] = contextvars.ContextVar("rtcli_served_files", default=None)
_stamps: contextvars.ContextVar[dict | None] = contextvars.ContextVar("rtcli_stamps", default=None)


NUL = "a path cannot hold a NUL byte"


class InputError(OSError):
    """A path that names no readable regular file of an allowed size; strerror says why
    (without the path, as OSError's strerror)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.strerror = reason

    def __str__(self) -> str:
        return self.strerror


def has_nul(path) -> bool:
    """Whether a path (str, bytes or os.PathLike) holds a NUL byte, which no file name can."""
    name = os.fspath(path)
    return ("\0" if isinstance(name, str) else b"\0") in name


def kind_of(mode: int) -> str:
    """'a folder', 'a FIFO (named pipe)', ... for a file mode that is not a regular file."""
    return next((name for test, name in _KINDS if test(mode)), "a special file")


def check_input(path: str, limit: int) -> int:
    """The size of the regular file at `path`; InputError (or FileNotFoundError) otherwise (a
    path with a NUL byte, which no file has, is an InputError too).

    Uses os.stat, which never opens the file, so a FIFO or a device is refused
    before anything could block on it or read it without end.
    """
    served = _served.get()
    if served is not None:
        if path not in served:
            raise FileNotFoundError(path)
        real, data = served[path]
        if len(data) > limit:
            raise InputError(f"too large: {len(data) / MB:.1f} MB, more than the {limit // MB} MB allowed")
        return len(data)
    if has_nul(path):
        raise InputError(NUL)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        _stamp(path, None)
        raise
    except OSError as e:
        raise InputError(e.strerror or str(e)) from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(f"not a regular file but {kind_of(st.st_mode)}")
    _stamp(path, st)
    if st.st_size > limit:
        raise InputError(f"too large: {st.st_size / MB:.1f} MB, more than the {limit // MB} MB allowed")
    _record(path)
    return st.st_size


def read_bytes(path: str, limit: int) -> bytes:
    """The whole content of a checked regular file, never more than `limit` bytes."""
    size = check_input(path, limit)
    served = _served.get()
    if served is not None:
        return served[path][1]
    with open(path, "rb") as f:
        data = f.read(size + 1)                   # read(n) reserves n bytes: ask for what stat said
        if len(data) > size:
            data += f.read(limit + 1 - len(data))
    if len(data) > limit:
        raise InputError(f"too large: it grew past the {limit // MB} MB allowed while being read")
    kept = _kept.get()
    if kept is not None:
        kept[path] = (os.path.realpath(path), data)
    return data


def real_path(path: str) -> str:
    """The file's real path (links resolved), as the machine that read it saw it when it is served;
    a path with a NUL byte as it is (no file has it: reading it is the error, check_input)."""
    if has_nul(path):
        return path
    served = _served.get()
    if served is not None and path in served:
        return served[path][0]
    return os.path.realpath(path)


@contextlib.contextmanager
def _set(var: contextvars.ContextVar, value):
    """`var` is `value` inside the block, which gets `value`."""
    token = var.set(value)
    try:
        yield value
    finally:
        var.reset(token)


def collecting():
    """Keeps, in a dict path -> (real path, bytes), every file read inside the block."""
    return _set(_kept, {})


def serving(files: dict):
    """Inside the block, files are read from `files` (path -> (real path, bytes), as `collecting`
    keeps them) instead of the disk; a path it lacks is not found."""
    return _set(_served, files)


def _record(path: str) -> None:
    read = _read.get()
    if read is not None:
        read.append(os.path.realpath(path))


def recording_inputs():
    """Collects the real path of every input checked inside the block, in a list."""
    return _set(_read, [])


@contextlib.contextmanager
def reading_scene():
    """Loading a scene: its inputs recorded (recording_inputs), with the cyclic garbage collector
    paused. Loading makes no cycles, and the collector would otherwise walk the growing tree
    again and again (a third of the time of a 100,000-object scene)."""
    collecting = gc.isenabled()
    gc.disable()
    try:
        with recording_inputs() as inputs:
            yield inputs
    finally:
        if collecting:
            gc.enable()


def stamp(st: os.stat_result | None):
    """What tells that a file changed: (size, mtime in ns, inode) of its stat, or None for no file.
    An editor that saves by writing a new file and renaming it changes the inode."""
    return None if st is None else (st.st_size, st.st_mtime_ns, st.st_ino)


def _stamp(path: str, st: os.stat_result | None) -> None:
    stamps = _stamps.get()
    if stamps is not None:
        stamps.setdefault(os.path.realpath(path), stamp(st))


def recording_stamps():
    """Collects, in a dict by real path, the stamp of every input checked inside the block as it
    was when checked, and None for one looked for and not found (the load then fails): what
    `rtcli render --watch` compares to see a change, even one made while it rendered."""
    return _set(_stamps, {})


@contextlib.contextmanager
def open_image(path: str):
    """A texture opened by Pillow after the checks above; a decompression bomb (more than
    MAX_TEXTURE_PIXELS texels, however small the file) is an InputError, not a warning."""
    source = path
    if _served.get() is not None or _kept.get() is not None:
        source = io.BytesIO(read_bytes(path, MAX_IMAGE_BYTES))
    else:
        check_input(path, MAX_IMAGE_BYTES)
    threshold, Image.MAX_IMAGE_PIXELS = Image.MAX_IMAGE_PIXELS, MAX_TEXTURE_PIXELS     # Pillow warns above it
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(source) as img:
                w, h = img.size
                if w * h > MAX_TEXTURE_PIXELS:
                    raise InputError(f"{w}x{h} is {w * h:,} texels, more than the {MAX_TEXTURE_PIXELS:,} allowed")
                yield img
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as e:
        raise InputError(f"refused as a decompression bomb: {' '.join(str(e).split())}") from None
    finally:
        Image.MAX_IMAGE_PIXELS = threshold
