"""A Dask scheduler file (`dask scheduler --scheduler-file PATH` writes it), read for `--cluster-file`
(README.md, Clusters): a small JSON object whose "address" is the scheduler's.

Only a regular file of at most MAX_BYTES is read. The file is opened without blocking
(a FIFO would wait for a writer) and checked on the open descriptor, so a file swapped
for a FIFO or a device (/dev/zero) between a check and the open is refused all the same,
and never more than MAX_BYTES + 1 bytes are read.
"""

from __future__ import annotations

import json
import os
import stat

from rtcli.errors import RtcliError, one_line, shown
from rtcli.scenefile.files import kind_of

MAX_BYTES = 64 * 1024                     # Dask's files are a few hundred bytes


def scheduler_address(path: str) -> str:
    """The address in the scheduler file at `path`; RtcliError naming the file (and the line and
    column of a JSON error, as json words them) otherwise."""
    what = f"--cluster-file {shown(path)}"
    text = _read(path, what)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise RtcliError(f"{what}: not a Dask scheduler file ({e})") from None      # e names line and column
    except RecursionError:
        raise RtcliError(f"{what}: not a Dask scheduler file: its JSON nests too deep") from None
    address = data.get("address") if isinstance(data, dict) else None
    if not isinstance(address, str) or not address:
        raise RtcliError(f"{what}: names no scheduler address (a JSON object with \"address\")")
    return address


def _read(path: str, what: str) -> str:
    """The text of a regular file of at most MAX_BYTES bytes, UTF-8."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise RtcliError(f"{what}: file not found") from None
    except OSError as e:
        raise RtcliError(f"{what}: cannot read: {one_line(e.strerror or str(e))}") from None
    except ValueError:                                       # a NUL byte in the path
        raise RtcliError(f"{what}: a path cannot hold a NUL byte") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise RtcliError(f"{what}: not a regular file but {kind_of(st.st_mode)}")
        if st.st_size > MAX_BYTES:
            raise RtcliError(f"{what}: too large for a scheduler file: {st.st_size:,} bytes, more than the "
                             f"{MAX_BYTES:,} allowed")
        data = os.read(fd, MAX_BYTES + 1)
    except OSError as e:
        raise RtcliError(f"{what}: cannot read: {one_line(e.strerror or str(e))}") from None
    finally:
        os.close(fd)
    if len(data) > MAX_BYTES:
        raise RtcliError(f"{what}: too large for a scheduler file: it grew past the {MAX_BYTES:,} bytes allowed")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise RtcliError(f"{what}: not a Dask scheduler file: byte {e.start} is not UTF-8") from None
