"""Trust: which machine code files may be opened, and how (rtcli/kernels/machinecode).

Opening a shared library runs its code, so a file is opened only when its folder and the file
belong to this user and are writable by no one else, and the file is a regular file (looked
at without following a link or opening a FIFO or a device): `trusted_folder` and
`private_bytes` check that and read the bytes once; `cut_short` finds an ELF library whose
headers reach past its end. `open_library` opens exactly the bytes checked, from a sealed
copy in memory (an anonymous memfd on Linux, else a copy in a private folder). Anything that
does not pass raises Refused (docs/architecture.md, Trust in the machine code files).
"""

from __future__ import annotations

import ctypes
import os
import stat
import struct
import tempfile
from pathlib import Path

try:
    import fcntl
except ImportError:                     # Windows: no memory files to seal
    fcntl = None


class Refused(Exception):
    """Why a machine code file is not opened (numba's path is taken instead)."""


def _private(info: os.stat_result, what: str) -> None:
    """Refused unless `info` (lstat or fstat) belongs to this user and no one else may write it."""
    if info.st_uid != os.geteuid():
        raise Refused(f"{what} belongs to another user (uid {info.st_uid})")
    if info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        raise Refused(f"{what} is writable by other users (mode {stat.S_IMODE(info.st_mode):o})")


def _checkable() -> bool:
    """Whether this platform lets the files be checked without following links (O_NOFOLLOW,
    opening relative to a folder's descriptor)."""
    return hasattr(os, "O_NOFOLLOW") and hasattr(os, "geteuid") and os.open in os.supports_dir_fd


def trusted_folder(place: Path) -> int:
    """An open descriptor of the folder `place`, once it is a folder of this user that no one
    else may write (so that no one else can add, replace or rename a file in it); Refused
    otherwise, FileNotFoundError when there is none."""
    if not _checkable():
        raise Refused("this platform cannot check them (no O_NOFOLLOW)")
    fd = os.open(place, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        info = os.fstat(fd)
        if not stat.S_ISDIR(info.st_mode):
            raise Refused(f"{place} is not a folder")
        _private(info, f"the folder {place}")
        return fd
    except BaseException:
        os.close(fd)
        raise


def private_bytes(folder_fd: int, name: str, limit: int) -> bytes:
    """The bytes of the file `name` in the open folder, read once, when it is a regular file of
    this user that no one else may write, of at most `limit` bytes; Refused otherwise. It is
    looked at (lstat) before it is opened, and opened without following a link and without
    waiting (a FIFO or a device is never opened; O_NONBLOCK in case one is swapped in)."""
    before = os.stat(name, dir_fd=folder_fd, follow_symlinks=False)
    if not stat.S_ISREG(before.st_mode):
        raise Refused(f"{name} is not a regular file")
    flags = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
    try:
        fd = os.open(name, flags, dir_fd=folder_fd)
    except OSError as e:
        raise Refused(f"{name} cannot be opened ({e.strerror})") from None
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or (info.st_dev, info.st_ino) != (before.st_dev, before.st_ino):
            raise Refused(f"{name} changed while it was opened")
        _private(info, name)
        data = f.read(limit + 1)
    if len(data) > limit:
        raise Refused(f"{name} is larger than {limit} bytes")
    return data


def cut_short(code: bytes) -> bool:
    """Whether an ELF library's program headers, segments or section headers reach past its end:
    the loader would map them, and reading there is SIGBUS. Other formats: False (the SHA-256
    is their check)."""
    if code[:4] != b"\x7fELF":
        return False
    if len(code) < 64 or code[4] not in (1, 2) or code[5] not in (1, 2):
        return True
    order, wide = "<" if code[5] == 1 else ">", code[4] == 2
    header = "QQIHHHHH" if wide else "IIIHHHHH"   # e_phoff, e_shoff, e_flags, e_ehsize, e_phentsize, e_phnum, ...
    phoff, shoff, _, _, phsize, phnum, shsize, shnum = struct.unpack_from(order + header, code, 32 if wide else 28)
    if phsize < (56 if wide else 32) or phoff + phnum * phsize > len(code) or (shoff and shoff + shnum * shsize >
                                                                             len(code)):
        return True
    segment = order + ("I 4x Q 16x Q" if wide else "I I 8x I").replace(" ", "")    # p_type, p_offset, p_filesz
    for k in range(phnum):
        _, offset, size = struct.unpack_from(segment, code, phoff + k * phsize)
        if offset + size > len(code):
            return True
    return False


_kept: list = []        # the memory files opened: their numbers, the libraries' names, are never reused


def open_library(code: bytes) -> ctypes.CDLL:
    """Open exactly the bytes `code` as a shared library: from a sealed anonymous memory file
    (Linux's memfd, named /proc/self/fd/N), else from a copy in a private folder, removed once
    open. OSError when the loader refuses it."""
    mode = os.RTLD_NOW | os.RTLD_LOCAL
    if hasattr(os, "memfd_create") and os.path.isdir("/proc/self/fd"):
        fd = os.memfd_create("rtcli-machine-code", os.MFD_CLOEXEC | getattr(os, "MFD_ALLOW_SEALING", 0))
        try:
            _write_all(fd, code)
            _seal(fd)
            library = ctypes.CDLL(f"/proc/self/fd/{fd}", mode=mode)
            _kept.append(fd)
            return library
        except OSError:
            os.close(fd)                         # e.g. memory files may not hold code here
    with tempfile.TemporaryDirectory(prefix="rtcli-machine-code-") as private:        # mode 0700
        path = os.path.join(private, "library.so")
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
        try:
            _write_all(fd, code)
        finally:
            os.close(fd)
        return ctypes.CDLL(path, mode=mode)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _seal(fd: int) -> None:
    """No one may change the memory file any more, this process included."""
    if fcntl is None:
        return                                   # the copy is still this process's own
    try:
        fcntl.fcntl(fd, fcntl.F_ADD_SEALS, fcntl.F_SEAL_SEAL | fcntl.F_SEAL_SHRINK | fcntl.F_SEAL_GROW |
                    fcntl.F_SEAL_WRITE)
    except (AttributeError, OSError):
        pass                                     # the copy is still this process's own
