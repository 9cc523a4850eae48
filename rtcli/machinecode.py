"""Machine code files: the compiled entry points run without loading numba.

numba's on-disk cache saves the minute of compiling, but a process that loads it still
imports numba and sets up its typing and lowering tables, about 0.4 s of every render:
more than the whole trace of a 640x480 image, and up to a second more when the 180 MB
LLVM library has to come back from disk. So when numba has compiled an entry point (the
integrator, compiled/integrator.py's trace_camera; the BVH build, core/bvh_build.py's
levels), `make` also writes its machine code as a small shared library beside numba's
cache (position-independent object code from numba's optimised module, linked by the C
compiler, `cc`), and `load` opens it with ctypes: no numba, no LLVM, about a millisecond.
It is the same code numba runs: the entry is wrapped in a C function (numba's cfunc) that
rebuilds the arguments from a flat list of words, so the pixels are the same bit for bit
(tests/test_machinecode.py).

The arguments of an entry are arrays, numbers, bools and namedtuples of those (the
compiled engine's Geometry and Looks). Their `layout` (each leaf's kind, an array's dtype
and number of dimensions, a namedtuple's fields) is fixed when the file is made; a call
passes each array as its address and shape (C order), each int and bool as a word and
each float as a float. A file is used only when its key matches this process: rtcli's
sources (the fingerprint compiled.drop_stale_cache keeps) and FORMAT, the CPU (its model
and features) and Python; and a call only when its arguments have the file's layout.
Otherwise the caller takes numba's path, which is slower to start and gives the same
numbers. Without a C compiler no file is made, and renders load numba as before.

Entries allocate nothing (the caller passes the output and scratch arrays), so the code
needs neither numba's runtime nor its helpers: the symbols it imports are the C library's
and Python's, which the process has (`load` checks), and a few of numba's on the paths
that raise a Python exception, which rtcli's kernels never take. The library is opened
with lazy binding, so those are never looked up.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from rtcli import variants

ENABLED = os.environ.get("RTCLI_MACHINE_CODE", "1") != "0"
SOURCES = ("variants.py", "core", "shapes", "compiled")     # what the machine code is made of
FORMAT = 2                              # of the files: a change to how they are made or called adds one
PACKAGE = Path(variants.PACKAGE_DIR)
ARGUMENTS = 3                           # the C function's: words (int64 *), floats (double *), results (int64 *)
HELPERS = ("NRT_", "numba_")            # numba's runtime and helpers: their symbols' prefixes


# --- what an entry's arguments look like ---
def layout(value) -> list:
    """The layout of an argument: ["a", dtype, ndim], ["i"], ["b"], ["f"], or ["t", [fields' layouts]]
    for a namedtuple; TypeError for anything else."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return ["a", value.dtype.str, value.ndim]
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return ["t", [layout(v) for v in value]]
    if isinstance(value, (bool, np.bool_)):
        return ["b"]
    if isinstance(value, (int, np.integer)):
        return ["i"]
    if isinstance(value, (float, np.floating)):
        return ["f"]
    raise TypeError(f"a machine code entry cannot take a {type(value).__name__}")


def flatten(value, words: list, floats: list, keep: list) -> None:
    """Append an argument to the call's words and floats (layout order); `keep` holds the arrays
    made C-contiguous for the call."""
    if isinstance(value, np.ndarray):
        if not value.flags.c_contiguous:
            value = np.ascontiguousarray(value)
            keep.append(value)
        words.append(value.ctypes.data)
        words.extend(value.shape)
    elif isinstance(value, tuple):
        for v in value:
            flatten(v, words, floats, keep)
    elif isinstance(value, (float, np.floating)):
        floats.append(float(value))
    else:
        words.append(int(value))


def wrapper_source(layouts: list, results: int) -> tuple[str, list]:
    """The C function's source, for arguments of these layouts and `results` int results; and the
    namedtuple slots it fills (names T0, T1 ... bound to the classes by the caller)."""
    counts, tuples = [0, 0], []

    def expr(lay, value_class):
        kind = lay[0]
        if kind == "a":
            k = counts[0]
            counts[0] += 1 + lay[2]
            shape = "".join(f"w[{k + 1 + j}], " for j in range(lay[2]))
            return f"carray(pointer(w[{k}], D{np.dtype(lay[1]).name}), ({shape}))"
        if kind == "t":
            name = f"T{len(tuples)}"
            tuples.append(value_class)
            return name + "(" + ", ".join(expr(f, c) for f, c in zip(lay[1], value_class[1])) + ")"
        if kind == "f":
            counts[1] += 1
            return f"f[{counts[1] - 1}]"
        counts[0] += 1
        return f"w[{counts[0] - 1}]" + (" != 0" if kind == "b" else "")

    args = [expr(lay, cls) for lay, cls in layouts]
    call = f"body({', '.join(args)})"
    lines = ["def entry(wp, fp, rp):", f"    w = carray(wp, ({max(counts[0], 1)},))",
             f"    f = carray(fp, ({max(counts[1], 1)},))"]
    if results:
        lines += [f"    r = carray(rp, ({results},))", f"    got = {call}"]
        lines += [f"    r[{k}] = got[{k}]" for k in range(results)]
    else:
        lines += [f"    {call}"]
    return "\n".join(lines) + "\n", tuples


def _classes(value):
    """The namedtuple classes of an argument, shaped as its layout: (class, [fields']) or None."""
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return type(value), [_classes(v) for v in value]
    return None


# --- the key: which process may use a file ---
def sources_digest(package: Path = PACKAGE) -> str:
    """SHA-256 of rtcli's sources that compiled code is made of (SOURCES, in `package`)."""
    digest = hashlib.sha256()
    for name in SOURCES:
        path = package / name
        for f in (sorted(path.glob("*.py")) if path.is_dir() else [path]):
            digest.update(f.name.encode() + f.read_bytes())
    return digest.hexdigest()


def _key() -> dict:
    return {"format": FORMAT, "sources": _digest(), "cpu": cpu(), "python": sys.implementation.cache_tag,
            "platform": sys.platform}


def cpu() -> str:
    """This CPU as machine code cares: its model and feature flags (Linux's /proc/cpuinfo), else
    what the platform module says."""
    try:
        with open("/proc/cpuinfo") as f:
            first = f.read().split("\n\n")[0]
        fields = dict(line.split(":", 1) for line in first.splitlines() if ":" in line)
        wanted = [fields.get(k, "").strip() for k in ("vendor_id", "model name", "flags", "Features", "CPU part")]
        if any(wanted):
            return hashlib.sha256("|".join(wanted).encode()).hexdigest()[:32]
    except OSError:
        pass
    return f"{platform.machine()} {platform.processor()}"


_digests: list = []


def _digest() -> str:
    if not _digests:
        _digests.append(sources_digest())
    return _digests[0]


def folder() -> Path | None:
    """Where the files are: numba's cache folder of rtcli/compiled (variants.cache_location), or None
    when there is no cache."""
    where = variants.cache_location()
    return Path(where.folders()[variants.COMPILED_DIRS.index("compiled")]) if where.enabled else None


def files(name: str, place: Path) -> tuple[Path, Path]:
    """The machine code (a shared library) and its description, for the entry `name`."""
    return place / f"rtcli-{name}.so", place / f"rtcli-{name}.json"


def compiler() -> str | None:
    """The C compiler that links the shared libraries: $CC, cc, gcc or clang."""
    found = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    return shutil.which(found) if found else None


# --- making a file (needs numba) ---
def make(name: str, dispatcher, args: tuple, results: int = 0) -> bool:
    """Write the machine code of numba's `dispatcher` (called with `args` once already) wrapped for
    calls with arguments of args' layout; whether it was written. It reaches into numba's
    code library for the object code, so any failure only means there is no file."""
    place, cc = folder(), compiler()
    if not ENABLED or place is None or cc is None:
        return False
    try:
        import llvmlite.binding as ll
        from numba import carray, cfunc
        from numba import types as nt
        source, tuples = wrapper_source([(layout(a), _classes(a)) for a in args], results)
        scope = {"carray": carray, "pointer": _pointer(), "body": dispatcher}
        scope.update({f"D{np.dtype(d).name}": np.dtype(d).type for d in _dtypes([layout(a) for a in args])})
        scope.update({f"T{k}": c[0] for k, c in enumerate(tuples)})
        exec(compile(source, f"<rtcli machine code entry {name}>", "exec"), scope)
        word, number = nt.CPointer(nt.int64), nt.CPointer(nt.float64)
        c = cfunc(nt.void(word, number, word), error_model="numpy")(scope["entry"])
        module = c._library._final_module                  # numba's optimised, linked module
        machine = ll.Target.from_triple(module.triple).create_target_machine(
            cpu=ll.get_host_cpu_name(), features=ll.get_host_cpu_features().flatten(), opt=3, reloc="pic",
            codemodel="default")
        imports = sorted({v.name for v in list(module.functions) + list(module.global_variables)
                          if v.is_declaration and not v.name.startswith("llvm.")})
        description = {"symbol": c.native_name, "layout": [layout(a) for a in args], "results": results,
                       "imports": imports, "key": _key()}
        library, about = files(name, place)
        with tempfile.TemporaryDirectory(dir=place) as work:
            code = Path(work, "entry.o")
            code.write_bytes(machine.emit_object(module))
            linked = Path(work, library.name)
            subprocess.run([cc, "-shared", "-o", str(linked), str(code), *_link_options()], check=True,
                           capture_output=True, timeout=120)
            os.replace(linked, library)
            written = Path(work, about.name)
            written.write_text(json.dumps(description))
            os.replace(written, about)          # the description last: a reader never sees it before its code
        _loaded.pop(name, None)
        return True
    except Exception:                       # another numba's internals, no linker, a full disk: numba's path
        return False


def _link_options() -> list[str]:
    """Unresolved symbols are the process's (Python's, numba's helpers): left to the loader."""
    if sys.platform == "darwin":
        return ["-undefined", "dynamic_lookup"]
    return ["-Wl,-z,lazy"]


def _dtypes(layouts: list):
    for lay in layouts:
        if lay[0] == "a":
            yield lay[1]
        elif lay[0] == "t":
            yield from _dtypes(lay[1])


def _pointer():
    """numba intrinsic pointer(address, dtype): the int64 address as a pointer to dtype."""
    from numba import types as nt
    from numba.extending import intrinsic

    @intrinsic
    def pointer(typingctx, address, dtype):
        to = nt.CPointer(dtype.dtype)

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(to))
        return to(nt.int64, dtype), codegen
    return pointer


# --- loading and calling (llvmlite only) ---
class Entry:
    """A loaded entry point: call it as the numba function, with arguments of its layout."""

    def __init__(self, function, layouts: list, results: int):
        self.function, self.layouts, self.results = function, layouts, results

    def fits(self, args: tuple) -> bool:
        """Whether args have the layout the machine code was made for."""
        try:
            return [layout(a) for a in args] == self.layouts
        except TypeError:
            return False

    def __call__(self, *args):
        words, floats, keep = [], [], []
        for a in args:
            flatten(a, words, floats, keep)
        w, f = np.array(words or [0], dtype=np.int64), np.array(floats or [0.0])
        r = np.zeros(max(self.results, 1), dtype=np.int64)
        self.function(w.ctypes.data, f.ctypes.data, r.ctypes.data)
        return tuple(int(x) for x in r[:self.results]) if self.results else None


_loaded: dict = {}


def load(name: str) -> Entry | None:
    """The entry `name` from its file, or None when there is none for this process (see the
    module's docstring). Loaded once a process; worker processes forked later share it."""
    if name in _loaded:
        return _loaded[name]
    _loaded[name] = entry = _read(name) if ENABLED else None
    return entry


def _read(name: str) -> Entry | None:
    place = folder()
    if place is None:
        return None
    library, about = files(name, place)
    try:
        description = json.loads(about.read_text())
        if description["key"] != _key() or not _present(description["imports"]):
            return None
        function = ctypes.CDLL(str(library), mode=os.RTLD_LAZY | os.RTLD_LOCAL)[description["symbol"]]
        function.restype, function.argtypes = None, [ctypes.c_void_p] * ARGUMENTS
        return Entry(function, description["layout"], int(description["results"]))
    except Exception:                       # missing, half-written, unreadable: numba's path
        return None


def _present(imports: list) -> bool:
    """Whether the process has every symbol the code imports, numba's HELPERS aside."""
    process = ctypes.CDLL(None)
    process.dlsym.restype, process.dlsym.argtypes = ctypes.c_void_p, [ctypes.c_void_p, ctypes.c_char_p]
    return all(symbol.startswith(HELPERS) or process.dlsym(None, symbol.encode()) for symbol in imports)


def entry(name: str, compiled: Callable, args: tuple) -> Callable:
    """The function to call with `args`: the machine code of `name` when loaded and args fit it,
    else numba's `compiled()` (which imports numba)."""
    found = load(name)
    return found if found is not None and found.fits(args) else compiled()
