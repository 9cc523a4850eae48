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
passes each array as its address and shape (C-contiguous, aligned arrays only), each int
and bool as a word and each float as a float. A file is used only when its key matches
this process: rtcli's sources (the fingerprint compiled.drop_stale_cache keeps) and this
module's, the CPU (its model and feature flags), numba, llvmlite and Python; and a call
only when its arguments have the file's layout. Otherwise the caller takes numba's path,
which is slower to start and gives the same numbers. Without a C compiler no file is
made, and renders load numba as before.

Entries allocate nothing (the caller passes the output and scratch arrays), so the code
needs neither numba's runtime nor its helpers: the symbols it imports are the C library's
and Python's, and a few of numba's on the paths that raise a Python exception, which
rtcli's kernels never take. Those are linked to stubs that say so on stderr and abort(),
so the library opens with every symbol bound (a missing one means numba's path).

Writing is atomic: the library's name holds a hash of its bytes, and the description
(.json), replaced last, names it.
"""

from __future__ import annotations

import ctypes
import hashlib
import importlib.metadata
import json
import os
import platform
import shlex
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
PACKAGE = Path(variants.PACKAGE_DIR)
ARGUMENTS = 3                           # the C function's: words (int64 *), floats (double *), results (int64 *)
HELPERS = ("NRT_", "numba_")            # numba's runtime and helpers: their symbols' prefixes


# --- what an entry's arguments look like ---
def layout(value) -> list:
    """The layout of an argument: ["a", dtype, ndim], ["i"] (int64), ["b"], ["f"] (float64), or
    ["t", [fields' layouts]] for a namedtuple; TypeError for anything else (a narrower scalar, a
    0-d array), which numba would type otherwise."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return ["a", value.dtype.str, value.ndim]
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return ["t", [layout(v) for v in value]]
    if isinstance(value, (bool, np.bool_)):
        return ["b"]
    if type(value) is int or type(value) is np.int64:
        return ["i"]
    if type(value) is float or type(value) is np.float64:
        return ["f"]
    raise TypeError(f"a machine code entry cannot take a {type(value).__name__}")


def passable(value) -> bool:
    """Whether every array of an argument can be passed by its address: C-contiguous and aligned
    (the C function writes where the caller reads)."""
    if isinstance(value, np.ndarray):
        return value.flags.c_contiguous and value.flags.aligned
    if isinstance(value, tuple):
        return all(passable(v) for v in value)
    return True


def flatten(value, words: list, floats: list) -> None:
    """Append an argument to the call's words and floats, in layout order."""
    if isinstance(value, np.ndarray):
        words.append(value.ctypes.data)
        words.extend(value.shape)
    elif isinstance(value, tuple):
        for v in value:
            flatten(v, words, floats)
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
    """The sources' digest and this module's, once a process."""
    if not _digests:
        _digests.append(sources_digest() + hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16])
    return _digests[0]


def folder() -> Path | None:
    """Where the files are: numba's cache folder of rtcli/compiled (variants.cache_location), or None
    when there is no cache."""
    where = variants.cache_location()
    return Path(where.folders()[variants.COMPILED_DIRS.index("compiled")]) if where.enabled else None


def description_file(name: str, place: Path) -> Path:
    """The description of the entry `name`: its key, layout, symbol and library file."""
    return place / f"rtcli-{name}.json"


def compiler() -> list[str] | None:
    """The C compiler command that links the shared libraries: $CC (may hold options), else cc,
    gcc or clang."""
    given = shlex.split(os.environ.get("CC", ""))
    if given:
        return [shutil.which(given[0]) or given[0], *given[1:]]
    found = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    return [found] if found else None


# --- making a file (needs numba) ---
def make(name: str, dispatcher, args: tuple, results: int = 0) -> str | None:
    """Write the machine code of numba's `dispatcher` (called with `args` once already) wrapped for
    calls with arguments of args' layout; None when written, else why not. It reaches into
    numba's code library for the optimised module, so a failure only means there is no file."""
    place, cc = folder(), compiler()
    if not ENABLED:
        return "RTCLI_MACHINE_CODE=0"
    if place is None:
        return "no cache folder"
    if cc is None:
        return "no C compiler (cc) to link them"
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
        helpers = sorted({v.name for v in module.functions if v.is_declaration and v.name.startswith(HELPERS)})
        with tempfile.TemporaryDirectory(dir=place) as work:
            objects = [Path(work, "entry.o"), Path(work, "stubs.o")]
            objects[0].write_bytes(machine.emit_object(module))
            objects[1].write_bytes(machine.emit_object(ll.parse_assembly(_stubs(helpers, module.triple))))
            linked = Path(work, "linked.so")
            subprocess.run([*cc, "-shared", "-o", str(linked), *map(str, objects), *_link_options()], check=True,
                           capture_output=True, timeout=120)
            code = linked.read_bytes()
            library = place / f"rtcli-{name}-{hashlib.sha256(code).hexdigest()[:16]}.so"
            os.replace(linked, library)
            description = {"symbol": c.native_name, "layout": [layout(a) for a in args], "results": results,
                           "library": library.name, "key": _key()}
            written = Path(work, "description.json")
            written.write_text(json.dumps(description))
            os.replace(written, description_file(name, place))      # the commit: it names the library
        for old in place.glob(f"rtcli-{name}-*.so"):
            if old != library:
                old.unlink(missing_ok=True)       # a process that opened it keeps its mapping
        _loaded.pop(name, None)
        return None
    except subprocess.CalledProcessError as e:
        return f"the C compiler failed: {(e.stderr or b'').decode(errors='replace').strip()[:200]}"
    except Exception as e:                  # another numba's internals, a full disk: numba's path
        return f"{type(e).__name__}: {e}"


def _stubs(names: list[str], triple: str) -> str:
    """LLVM IR defining numba's helper functions `names` as: say on stderr that the machine code
    took a path rtcli's kernels never take, then abort()."""
    text = (b"rtcli: the compiled engine's machine code reached numba's error handling; "
            b"run with RTCLI_MACHINE_CODE=0 to use numba itself\n")
    escaped = "".join(chr(b) if 32 <= b < 127 and b not in (34, 92) else f"\\{b:02X}" for b in text)
    lines = [f'target triple = "{triple}"',
             f'@rtcli_message = private constant [{len(text)} x i8] c"{escaped}"',
             "declare i64 @write(i32, i8*, i64)", "declare void @abort()"]
    for name in names:
        lines += [f'define void @"{name}"() {{',
                  f"  %m = getelementptr [{len(text)} x i8], [{len(text)} x i8]* @rtcli_message, i64 0, i64 0",
                  f"  %w = call i64 @write(i32 2, i8* %m, i64 {len(text)})",
                  "  call void @abort()", "  unreachable", "}"]
    return "\n".join(lines) + "\n"


def _link_options() -> list[str]:
    """The C library's math, and Python's symbols left to the process that opens the library."""
    if sys.platform == "darwin":
        return ["-lm", "-undefined", "dynamic_lookup"]
    return ["-lm"]


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


# --- loading and calling (ctypes only) ---
class Entry:
    """A loaded entry point: call it as the numba function, with arguments of its layout."""

    def __init__(self, function, layouts: list, results: int):
        self.function, self.layouts, self.results = function, layouts, results

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
    try:
        description = json.loads(description_file(name, place).read_text())
        if description["key"] != _key():
            return None
        library = place / Path(description["library"]).name
        function = ctypes.CDLL(str(library), mode=os.RTLD_NOW | os.RTLD_LOCAL)[description["symbol"]]
        function.restype, function.argtypes = None, [ctypes.c_void_p] * ARGUMENTS
        return Entry(function, description["layout"], int(description["results"]))
    except Exception:                       # missing, unreadable, a symbol not found: numba's path
        return None


def entry(name: str, compiled: Callable, args: tuple) -> Callable:
    """The function to call with `args`: the machine code of `name` when loaded and args fit it,
    else numba's `compiled()` (which imports numba)."""
    found = load(name)
    return found if found is not None and found.fits(args) else compiled()
