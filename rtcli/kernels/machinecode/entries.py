"""Loading and calling an entry point from its machine code file (rtcli/kernels/machinecode).

`load` reads an entry's description and library once a process, through every check of
trust.py, and gives an Entry (ctypes only: no numba, no LLVM), or None: then the caller takes
numba's path, and `report_to`'s listener hears why (once each reason). `entry` picks the
function a call takes: the machine code when its arguments fit the file's layout, else
numba's. A call that reaches numba's error handling comes back as Stopped.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from rtcli.kernels.machinecode import places  # ENABLED and folder() read when called: one switch, one place
from rtcli.kernels.machinecode.arguments import flatten, layout, passable
from rtcli.kernels.machinecode.places import ENTRY_SYMBOL, description_file, key
from rtcli.kernels.machinecode.trust import Refused, cut_short, open_library, private_bytes, trusted_folder

ARGUMENTS = 3                           # the C function's: words (int64 *), floats (double *), results (int64 *)
LIBRARY_LIMIT = 64 << 20                # bytes: the integrator's library is about 250 KB
DESCRIPTION_LIMIT = 1 << 20


class Stopped(RuntimeError):
    """The machine code reached numba's error handling (a path rtcli's kernels never take) and
    left at once; numba itself would have raised an exception there."""


class Entry:
    """A loaded entry point: call it as the numba function, with arguments of its layout."""

    def __init__(self, function, layouts: list, results: int, name: str = ""):
        self.function, self.layouts, self.results, self.name = function, layouts, results, name

    def fits(self, args: tuple) -> bool:
        """Whether args have the layout the machine code was made for, and arrays it can be given
        by address (passable)."""
        try:
            return [layout(a) for a in args] == self.layouts and all(passable(a) for a in args)
        except TypeError:
            return False

    def __call__(self, *args):
        words, floats = [], []
        for a in args:
            flatten(a, words, floats)
        w, f = np.array(words or [0], dtype=np.int64), np.array(floats or [0.0])
        r = np.zeros(max(self.results, 1), dtype=np.int64)
        if self.function(w.ctypes.data, f.ctypes.data, r.ctypes.data):
            raise Stopped(f"the machine code of {self.name or 'an entry'} reached numba's error handling; "
                          "run with RTCLI_MACHINE_CODE=0 for numba's own error")
        return tuple(int(x) for x in r[:self.results]) if self.results else None


_loaded: dict = {}
_listeners: list = []
_told: set = set()


def report_to(notes: Callable[[str], None] | None) -> None:
    """Say to `notes` (once each) why a machine code file is not used; None: say nothing (the
    default)."""
    _listeners[:] = [notes] if notes else []


def load(name: str) -> Entry | None:
    """The entry `name` from its file, or None when there is none for this process or it cannot
    be trusted (see the package's docstring). Loaded once a process; worker processes forked
    later share it."""
    if name in _loaded:
        return _loaded[name]
    _loaded[name] = entry = _read(name) if places.ENABLED else None
    return entry


def forget(name: str) -> None:
    """Load `name` again when next asked for (its file was written again)."""
    _loaded.pop(name, None)


def _read(name: str) -> Entry | None:
    place = places.folder()
    if place is None:
        return None
    try:
        return _trusted_entry(name, place)
    except FileNotFoundError:               # never written (or half of a pair): nothing to say
        return None
    except Refused as e:
        _tell(str(e))
    except Exception as e:                  # unreadable, not JSON, a symbol not found: numba's path
        _tell(f"{description_file(name, place).name}: {type(e).__name__}: {e}")
    return None


def _tell(why: str) -> None:
    if _listeners and why not in _told:
        _told.add(why)
        _listeners[0](f"machine code file not used, numba's path instead: {why}")


def _trusted_entry(name: str, place: Path) -> Entry:
    """The entry `name` from the folder `place` once every check of the package's docstring
    passed; Refused (or FileNotFoundError) otherwise."""
    folder_fd = trusted_folder(place)
    try:
        about = description_file(name, place).name
        description = json.loads(private_bytes(folder_fd, about, DESCRIPTION_LIMIT))
        if not isinstance(description, dict):
            raise Refused(f"{about} is not a description")
        if description.get("key") != key():
            raise Refused(f"{about} was made for another process (rtcli's sources, the CPU, numba or Python)")
        if description.get("symbol") != ENTRY_SYMBOL:
            raise Refused(f"{about} names {str(description.get('symbol'))[:80]!r} as its entry, not {ENTRY_SYMBOL}")
        library, results = str(description.get("library")), description.get("results")
        if not re.fullmatch(rf"rtcli-{re.escape(name)}-[0-9a-f]{{16}}\.so", library):
            raise Refused(f"{about} names a library that is not one of its own")
        if type(results) is not int or not 0 <= results <= 64 or not isinstance(description.get("layout"), list):
            raise Refused(f"{about} is not a description")
        code = private_bytes(folder_fd, library, LIBRARY_LIMIT)
    finally:
        os.close(folder_fd)
    if hashlib.sha256(code).hexdigest() != description.get("sha256"):
        raise Refused(f"{library} does not have the SHA-256 recorded when it was written")
    if cut_short(code):
        raise Refused(f"{library} is cut short")
    try:
        function = open_library(code)[ENTRY_SYMBOL]
    except (OSError, AttributeError) as e:
        raise Refused(f"{library} cannot be opened ({str(e)[:200]})") from None
    function.restype, function.argtypes = ctypes.c_int, [ctypes.c_void_p] * ARGUMENTS
    return Entry(function, description["layout"], results, name)


def entry(name: str, compiled: Callable, args: tuple) -> Callable:
    """The function to call with `args`: the machine code of `name` when loaded and args fit it,
    else numba's `compiled()` (which imports numba)."""
    found = load(name)
    return found if found is not None and found.fits(args) else compiled()
