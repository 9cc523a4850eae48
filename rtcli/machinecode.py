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

Trust (docs/architecture.md, Trust in the machine code files). Opening a shared library
runs its code, so a file is opened only when its folder, its description and its library
belong to this user and are writable by no one else, the two files are regular files
(looked at without following a link or opening a FIFO or a device), and the library's
bytes have the SHA-256 the description recorded when it was written. The library is read
once, checked, and opened from a sealed copy in memory (an anonymous memfd on Linux, else a
copy in a private folder): the bytes opened are the bytes checked. Anything that does not
pass means numba's path, said in one line to whoever listens (`report_to`: `--stats`).

Entries allocate nothing (the caller passes the output and scratch arrays), so the code
needs neither numba's runtime nor its helpers: `helper_calls` reads the module and finds
the calls of numba's helpers (NRT_*, numba_*) and of Python's C API that a call can make
without raising an exception; a module with one is refused when it is written. The
others lie on the paths that raise an exception, which rtcli's kernels never take; they
are linked to stubs that leave the machine code at once (a longjmp to the C function
rtcli calls), so the call returns to Python, which raises Stopped: never abort().

Writing is atomic: the library's name holds a hash of its bytes, and the description
(.json), replaced last, names it and records its SHA-256.
"""

from __future__ import annotations

import ctypes
import hashlib
import importlib.metadata
import json
import os
import platform
import re
import shlex
import shutil
import stat
import struct
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
FOREIGN = ("NRT_", "numba_", "Py", "_Py")   # numba's runtime and helpers, Python's C API: their symbols' prefixes
ENTRY_SYMBOL = "rtcli_entry"            # the C function rtcli calls, the one symbol a description may name
BODY_SYMBOL = "rtcli_body"              # numba's cfunc, renamed in the library, hidden
LIBRARY_LIMIT = 64 << 20                # bytes: the integrator's library is about 250 KB
DESCRIPTION_LIMIT = 1 << 20


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
        os.close(_trusted_folder(place))
        machine, module = _module(name, dispatcher, args, results)
        text = str(module)
        found = helper_calls(text, BODY_SYMBOL)
        if found:
            caller, callee = found[0]
            return f"refused: it would call {callee} (from {readable(caller)}) on a path that raises no exception"
        with tempfile.TemporaryDirectory(dir=place) as work:
            objects = [Path(work, "entry.o"), Path(work, "wrapper.c")]
            objects[0].write_bytes(machine.emit_object(module))
            objects[1].write_text(wrapper_c(*foreign_symbols(text)))
            linked = Path(work, "linked.so")
            subprocess.run([*cc, "-shared", "-fPIC", "-O2", "-o", str(linked), *map(str, objects), *_link_options()],
                           check=True, capture_output=True, timeout=120)
            _commit(name, place, linked, {"layout": [layout(a) for a in args], "results": results})
        return None
    except Refused as e:
        return str(e)
    except subprocess.CalledProcessError as e:
        return f"the C compiler failed: {(e.stderr or b'').decode(errors='replace').strip()[:200]}"
    except Exception as e:                  # another numba's internals, a full disk: numba's path
        return f"{type(e).__name__}: {e}"


def _module(name: str, dispatcher, args: tuple, results: int):
    """(a target machine for this CPU, a copy of numba's optimised module of the entry's cfunc,
    the cfunc renamed BODY_SYMBOL and hidden)."""
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
    module = c._library._final_module.clone()          # numba's optimised, linked module
    body = module.get_function(c.native_name)
    body.name, body.visibility = BODY_SYMBOL, ll.Visibility.hidden
    machine = ll.Target.from_triple(module.triple).create_target_machine(
        cpu=ll.get_host_cpu_name(), features=ll.get_host_cpu_features().flatten(), opt=3, reloc="pic",
        codemodel="default")
    return machine, module


def _commit(name: str, place: Path, linked: Path, description: dict) -> None:
    """Move the library `linked` into place, named by its hash, then its description (the commit:
    it names the library and records its SHA-256); both writable by no one else, whatever the
    umask. Older libraries of the entry are removed (a process that opened one keeps it)."""
    code = linked.read_bytes()
    digest = hashlib.sha256(code).hexdigest()
    library = place / f"rtcli-{name}-{digest[:16]}.so"
    os.chmod(linked, 0o644)
    os.replace(linked, library)
    written = linked.with_name("description.json")
    written.write_text(json.dumps({"symbol": ENTRY_SYMBOL, "sha256": digest, **description, "library": library.name,
                                   "key": _key()}))
    os.chmod(written, 0o644)
    os.replace(written, description_file(name, place))
    for old in place.glob(f"rtcli-{name}-*.so"):
        if old != library:
            old.unlink(missing_ok=True)
    _loaded.pop(name, None)


def wrapper_c(functions: list[str], data: list[str]) -> str:
    """C source of the library's entry, `rtcli_entry(words, floats, results)`: it calls numba's cfunc
    and returns 0, or 1 when the machine code reached one of the foreign `functions` (numba's
    helpers, Python's C API), each defined here as a stub that jumps straight back to it
    (longjmp: no helper runs, nothing is left half done but the caller's arrays). `data`: the
    foreign variables (Python's exception types), defined so that every symbol is bound."""
    lines = ["#include <setjmp.h>", "#include <stdint.h>", '#define HIDDEN __attribute__((visibility("hidden")))',
             f"HIDDEN void {BODY_SYMBOL}(int64_t *, double *, int64_t *);",
             "static __thread jmp_buf *way_out;        /* per thread: the call in progress */",
             f"int {ENTRY_SYMBOL}(int64_t *words, double *floats, int64_t *results) {{",
             "    jmp_buf here;", "    jmp_buf *outer = way_out;",
             "    if (setjmp(here)) { way_out = outer; return 1; }",
             "    way_out = &here;", f"    {BODY_SYMBOL}(words, floats, results);",
             "    way_out = outer;", "    return 0;", "}",
             "HIDDEN void rtcli_helper_reached(void) { if (way_out) longjmp(*way_out, 1); }"]
    lines += [f"HIDDEN intptr_t {f}(void) {{ rtcli_helper_reached(); return 0; }}" for f in functions]
    lines += [f"HIDDEN void *{d}[8];" for d in data]
    return "\n".join(lines) + "\n"


def _link_options() -> list[str]:
    """The C library's math."""
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


# --- which of numba's helpers a call can reach (read from the module's LLVM IR) ---
# numba's functions return a status (numba/core/callconv.py): 0, or -2 for None, when they
# return; any other value when they raise, the exception described in *excinfo. A helper call
# lies on a path that raises when its block returns an error status whatever happens next
# ("doomed"; a call's status past the branch that found it failed counts as one), or, in the C
# function (which returns no status), when it is reached only past such a branch, to report
# it. A function whose failure its caller does not pass on (as numba's try/except would) has
# no such path: all of it may run on a call that returns. Nothing else may touch numba's
# runtime or Python: `helper_calls` lists what does.
_NAME = r'(?:"(?:[^"\\]|\\.)*"|[-\w$.]+)'
_DEFINE = re.compile(r"^define\b[^@]*@(" + _NAME + r")\((.*)$")
_DECLARE = re.compile(r"^declare\b[^@]*@(" + _NAME + r")\(")
_EXTERNAL = re.compile(r"^@(" + _NAME + r") = (?:\w+ )*external\b")
_GLOBAL = re.compile(r"^@(" + _NAME + r") = ")
_LABEL = re.compile(r"^(" + _NAME + r"):")
_REF = re.compile(r"@(" + _NAME + r")")
_CALL = re.compile(r"\bcall\b.*?([@%]" + _NAME + r")\(")
_TARGET = re.compile(r"label %(" + _NAME + r")")
_ASSIGN = re.compile(r"^%(" + _NAME + r") = (.*)$")
_RANGE = re.compile(r"\brange\(i32 (-?\d+), (-?\d+)\)")
_BRANCH = re.compile(r"^br i1 %(" + _NAME + r"), label %(" + _NAME + r"), label %(" + _NAME + r")")
_COMPARE = re.compile(r"^icmp (eq|ne) i32 (%" + _NAME + r"|-?\d+), (%" + _NAME + r"|-?\d+)$")
_SWITCH = re.compile(r"^switch i32 %(" + _NAME + r"), label %(" + _NAME + r") \[(.*)\]")
_CASE = re.compile(r"i32 (-?\d+), label %(" + _NAME + r")")
_RETURN = re.compile(r"^ret i32 %(" + _NAME + r")$")
_INCOMING = re.compile(r"\[\s*([^,\]]+?),\s*%(" + _NAME + r")\s*\]")
RETURNED = (0, -2)                      # the statuses of a function that returned (not raised)
ALLOWED = {("NRT_decref", "NRT_MemInfo_call_dtor")}
# NRT_decref (numba's own, in the module) calls the destructor when a count falls to zero,
# and only an allocation (NRT_MemInfo_alloc..., which helper_calls finds) makes a count: the
# arrays an entry gets come from carray, with none (their meminfo is null).


def _unquote(name: str) -> str:
    return name[1:-1] if name.startswith('"') else name


class _Function:
    """A function of the module as its text gives it: blocks (label -> instructions) in order."""

    def __init__(self, name: str, header: str):
        self.name, self.blocks = name, {}
        signature = header[:header.index("@")]
        self.status = re.search(r"\bi32\s*$", signature) is not None and "%excinfo" in header
        bounds = _RANGE.search(signature)             # LLVM's proof of the statuses it returns
        self.never_none = bounds is not None and not _within(int(bounds[1]), int(bounds[2]), -2)

    def finish(self) -> None:
        self.values = {_unquote(m[1]): m[2] for code in self.blocks.values() for line in code
                       if (m := _ASSIGN.match(line))}
        self.successors = {b: _successors(code[-1]) if code else [] for b, code in self.blocks.items()}
        self.predecessors = {b: set() for b in self.blocks}
        for b, after in self.successors.items():
            for s in after:
                self.predecessors.setdefault(s, set()).add(b)


def _within(low: int, high: int, x: int) -> bool:
    """Whether x lies in LLVM's range(low, high): [low, high), wrapping when low > high."""
    return low <= x < high if low < high else (x >= low or x < high)


def _successors(last: str) -> list[str]:
    if last.startswith(("ret", "unreachable")):
        return []
    return list(dict.fromkeys(_unquote(t) for t in _TARGET.findall(last)))


def parse_module(text: str) -> tuple[dict, set, set]:
    """The module's defined functions ({name: _Function}), its external symbols, and the
    functions global variables' initialisers name (called from anywhere: roots)."""
    functions, external, rooted, current, block = {}, set(), set(), None, None
    for line in text.splitlines():
        if current is None:
            if m := _DEFINE.match(line):
                current, block = _Function(_unquote(m[1]), line), None
                functions[current.name] = current
            elif m := _DECLARE.match(line) or _EXTERNAL.match(line):
                external.add(_unquote(m[1]))
            elif m := _GLOBAL.match(line):
                rooted.update(_unquote(r) for r in _REF.findall(line[m.end():]))
            continue
        if line.startswith("}"):
            current.finish()
            current = None
            continue
        code = line.split(";")[0].strip() if not line.lstrip().startswith(";") else ""
        if not code:
            continue
        if not line[0].isspace() and (m := _LABEL.match(line)):
            block = current.blocks[_unquote(m[1])] = []
        elif block is None:
            block = current.blocks[""] = [code]
        elif block and block[-1].startswith("switch") and "]" not in block[-1]:
            block[-1] += " " + code               # a switch's cases, one a line
        else:
            block.append(code)
    return functions, external, rooted & set(functions)


def _constant_error(value: str) -> bool:
    try:
        return int(value) not in RETURNED
    except ValueError:
        return False


class _Flow:
    """Where a function raises: the branches a failed call's status takes (`edges`), the blocks
    reached only through them with the statuses known there to be errors (`failed`), and the
    blocks that return an error status whatever happens next (`doomed`)."""

    def __init__(self, f: _Function, functions: dict):
        self.f, self.functions = f, functions
        self.edges = self._failure_edges()
        self.failed = self._failed()
        self.doomed = self._doomed()

    def status_callee(self, line: str) -> _Function | None:
        """The function returning a status (numba's) that `line` calls directly, if any."""
        called = _CALL.search(line)
        g = self.functions.get(_unquote(called[1][1:])) if called and called[1][0] == "@" else None
        return g if g is not None and g.status else None

    def _failure_edges(self) -> dict:
        """{(block, target): status} for the ways a branch on a call's status takes when it is an
        error: `br i1 (status == 0)`'s false way (!= 0's true way) when the callee cannot return
        -2 (LLVM's range says so); a `switch` on it: the cases other than 0 and -2, and its
        default when both are cases (or the callee cannot return -2)."""
        edges = {}
        for b, code in self.f.blocks.items():
            last = code[-1] if code else ""
            for status, target in self._branch_failures(last) + self._switch_failures(last):
                edges[(b, target)] = status
        return edges

    def _branch_failures(self, last: str) -> list:
        branch = _BRANCH.match(last)
        compare = _COMPARE.match(self.f.values.get(_unquote(branch[1]), "")) if branch else None
        if not compare or "0" not in (compare[2], compare[3]) or branch[2] == branch[3]:
            return []
        status = _unquote((compare[3] if compare[2] == "0" else compare[2])[1:])
        callee = self.status_callee(self.f.values.get(status, ""))
        if callee is None or not callee.never_none:
            return []
        return [(status, _unquote(branch[3] if compare[1] == "eq" else branch[2]))]

    def _switch_failures(self, last: str) -> list:
        switch = _SWITCH.match(last)
        callee = self.status_callee(self.f.values.get(_unquote(switch[1]), "")) if switch else None
        if callee is None:
            return []
        cases = [(int(v), _unquote(t)) for v, t in _CASE.findall(switch[3])]
        returned = {t for v, t in cases if v in RETURNED}
        failures = [t for v, t in cases if v not in RETURNED]
        values = {v for v, _ in cases}
        if 0 in values and (-2 in values or callee.never_none):
            failures.append(_unquote(switch[2]))
        return [(_unquote(switch[1]), t) for t in dict.fromkeys(failures) if t not in returned]

    def _failed(self) -> dict:
        """{block: statuses that are errors there} for the blocks reached only past a failure edge:
        the least set of blocks, then the statuses narrowed from all of them (a must-analysis)."""
        before, raised, changed = self.f.predecessors, set(), True
        while changed:
            changed = False
            for b, came in before.items():
                if b not in raised and came and ((len(came) == 1 and (next(iter(came)), b) in self.edges) or
                                                 came <= raised):
                    raised.add(b)
                    changed = True
        everything = frozenset(self.edges.values())
        failed = {b: everything for b in raised}
        changed = True
        while changed:
            changed = False
            for b in raised:
                came = before[b]
                if len(came) == 1 and (p := next(iter(came)), b) in self.edges:
                    now = failed.get(p, frozenset()) | {self.edges[(p, b)]}
                else:
                    now = frozenset.intersection(*(failed[p] for p in came))
                if now != failed[b]:
                    failed[b], changed = now, True
        return failed

    def returns_error(self, b: str, value: str) -> bool:
        """Whether `value`, returned from block b, is an error status: a constant, or a failed call's."""
        return _constant_error(value) or (value.startswith("%") and _unquote(value[1:]) in self.failed.get(b, ()))

    def _doomed(self) -> set[str]:
        """The greatest set of blocks every way out of which returns an error status (or never returns)."""
        if not self.f.status:
            return set()
        doomed, changed = set(self.f.blocks), True
        while changed:
            changed = False
            for b in list(doomed):
                if not self._dooms(b, doomed):
                    doomed.discard(b)
                    changed = True
        return doomed

    def _dooms(self, b: str, doomed: set) -> bool:
        last = self.f.blocks[b][-1] if self.f.blocks[b] else ""
        if last.startswith("unreachable"):
            return True
        if last.startswith("ret"):
            return self.returns_error(b, last.split()[-1])
        if not last.startswith(("br ", "switch ")) or not self.f.successors[b]:
            return False
        return all(self._edge_dooms(b, s, doomed) for s in self.f.successors[b])

    def _edge_dooms(self, b: str, s: str, doomed: set, failing: str = "") -> bool:
        """Whether going from b to s raises: s is doomed, or s returns a status that is an error
        in b or is `failing` (the value b hands a phi of s, or one s returns as it is)."""
        value = self._returned(b, s)
        if value is not None:
            return self.returns_error(b, value) or value == f"%{failing}"
        return s in doomed

    def _returned(self, b: str, s: str) -> str | None:
        """The status block s returns when reached from b (a value, or the value b hands a phi
        of s), or None when s returns none."""
        code = self.f.blocks.get(s) or [""]
        returned = _RETURN.match(code[-1])
        if returned is None:
            return None
        value, phi = "%" + returned[1], self.f.values.get(_unquote(returned[1]), "")
        if phi.startswith("phi ") and any(line.startswith(value + " = phi ") for line in code):
            value = {_unquote(block): v.strip() for v, block in _INCOMING.findall(phi)}.get(b, "0")
        return value

    def safe(self) -> set[str]:
        """The blocks that run only when the call raises: doomed ones; in the C function (which
        returns no status), the ones past a failure, which report it."""
        return self.doomed if self.f.status else set(self.failed)

    def swallowed(self, blocks) -> set[str]:
        """The functions called in `blocks` whose failure this one does not pass on: it goes on as
        if they had returned (their error paths then run on a call that returns)."""
        found = set()
        for b in blocks:
            for line in self.f.blocks[b]:
                callee = self.status_callee(line)
                assigned = _ASSIGN.match(line)
                if callee is not None and (assigned is None or not self._passes_on(_unquote(assigned[1]), b)):
                    found.add(callee.name)
        return found

    def _passes_on(self, status: str, b: str) -> bool:
        """Whether the failure of the call in block b (giving `status`) makes this function fail: its
        failure edges raise (in the C function: report), or b goes on to return the status as it is."""
        edges = [(p, t) for (p, t), s in self.edges.items() if s == status]
        if not self.f.status:
            return bool(edges)
        if edges:
            return all(self._edge_dooms(p, t, self.doomed, status) for p, t in edges)
        last = self.f.blocks[b][-1]
        if last.startswith("br label %"):
            return self._returned(b, _unquote(last[len("br label %"):])) == f"%{status}"
        return last == f"ret i32 %{status}"


def foreign_symbols(text: str) -> tuple[list[str], list[str]]:
    """The module's external functions and variables of numba's runtime and helpers and of
    Python's C API (FOREIGN): the library defines them as stubs (wrapper_c)."""
    functions, variables = [], []
    for line in text.splitlines():
        m = _DECLARE.match(line) or _EXTERNAL.match(line)
        if m and _unquote(m[1]).startswith(FOREIGN):
            name = _unquote(m[1])
            if not re.fullmatch(r"[A-Za-z_]\w*", name):
                raise ValueError(f"cannot link a stub for {name!r}")
            (functions if line.startswith("declare") else variables).append(name)
    return sorted(set(functions)), sorted(set(variables))


def helper_calls(text: str, root: str) -> list[tuple[str, str]]:
    """The (function, foreign symbol) pairs of the module `text` (LLVM IR) in which a call of
    the function `root` can reach numba's runtime or helpers or Python's C API without raising
    an exception: the blocks that are not `_Flow.safe`, of `root`, of the functions global
    variables name and of the functions such blocks call or take the address of (all blocks of a
    function whose failure is not passed on, and of any function whose address is taken when
    such a block calls through a pointer)."""
    functions, external, rooted = parse_module(text)
    foreign = {name for name in external if name.startswith(FOREIGN)}
    flows, reached, found, pointers = {}, set(), [], False
    todo = [(root, False), *((name, False) for name in rooted)]
    while todo:
        name, strict = todo.pop()
        if name not in functions or (name, strict) in reached or (name, True) in reached:
            continue
        reached.add((name, strict))
        f = functions[name]
        flow = flows[name] = flows.get(name) or _Flow(f, functions)
        blocks = list(f.blocks) if strict else [b for b in f.blocks if b not in flow.safe()]
        swallowed = set() if strict else flow.swallowed(blocks)
        for b in blocks:
            for line in f.blocks[b]:
                called = _CALL.search(line)
                pointers = pointers or (called is not None and called[1][0] == "%")
                for ref in (_unquote(r) for r in _REF.findall(line)):
                    if ref in foreign and (name, ref) not in ALLOWED:
                        found.append((name, ref))
                    todo.append((ref, strict or ref in swallowed))
        if not todo and pointers:
            todo = [(n, True) for n in functions if (n, True) not in reached and _address_taken(n, functions)]
    return list(dict.fromkeys(found))


def _address_taken(name: str, functions: dict) -> bool:
    for f in functions.values():
        for code in f.blocks.values():
            for line in code:
                called = _CALL.search(line)
                refs = [_unquote(r) for r in _REF.findall(line)]
                if called and called[1][0] == "@" and _unquote(called[1][1:]) == name:
                    refs.remove(name)
                if name in refs:
                    return True
    return False


def readable(symbol: str) -> str:
    """A numba function's symbol as its Python name: _ZN5rtcli6shapes7polygon3hitB4v129... ->
    rtcli.shapes.polygon.hit."""
    if not symbol.startswith("_ZN"):
        return symbol
    parts, rest = [], symbol[3:]
    while (m := re.match(r"(\d+)", rest)) and int(m[1]) > 0:
        size = int(m[1])
        parts.append(rest[len(m[1]):len(m[1]) + size])
        rest = rest[len(m[1]) + size:]
    return ".".join(parts) or symbol


# --- trust: which files may be opened ---
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


def _trusted_folder(place: Path) -> int:
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


def _private_bytes(folder_fd: int, name: str, limit: int) -> bytes:
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


def _open_library(code: bytes) -> ctypes.CDLL:
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
    try:
        import fcntl
        fcntl.fcntl(fd, fcntl.F_ADD_SEALS, fcntl.F_SEAL_SEAL | fcntl.F_SEAL_SHRINK | fcntl.F_SEAL_GROW |
                    fcntl.F_SEAL_WRITE)
    except (ImportError, AttributeError, OSError):
        pass                                     # the copy is still this process's own


# --- loading and calling (ctypes only) ---
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
    be trusted (see the module's docstring). Loaded once a process; worker processes forked
    later share it."""
    if name in _loaded:
        return _loaded[name]
    _loaded[name] = entry = _read(name) if ENABLED else None
    return entry


def _read(name: str) -> Entry | None:
    place = folder()
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
    """The entry `name` from the folder `place` once every check of the module's docstring
    passed; Refused (or FileNotFoundError) otherwise."""
    folder_fd = _trusted_folder(place)
    try:
        about = description_file(name, place).name
        description = json.loads(_private_bytes(folder_fd, about, DESCRIPTION_LIMIT))
        if not isinstance(description, dict):
            raise Refused(f"{about} is not a description")
        if description.get("key") != _key():
            raise Refused(f"{about} was made for another process (rtcli's sources, the CPU, numba or Python)")
        if description.get("symbol") != ENTRY_SYMBOL:
            raise Refused(f"{about} names {str(description.get('symbol'))[:80]!r} as its entry, not {ENTRY_SYMBOL}")
        library, results = str(description.get("library")), description.get("results")
        if not re.fullmatch(rf"rtcli-{re.escape(name)}-[0-9a-f]{{16}}\.so", library):
            raise Refused(f"{about} names a library that is not one of its own")
        if type(results) is not int or not 0 <= results <= 64 or not isinstance(description.get("layout"), list):
            raise Refused(f"{about} is not a description")
        code = _private_bytes(folder_fd, library, LIBRARY_LIMIT)
    finally:
        os.close(folder_fd)
    if hashlib.sha256(code).hexdigest() != description.get("sha256"):
        raise Refused(f"{library} does not have the SHA-256 recorded when it was written")
    if cut_short(code):
        raise Refused(f"{library} is cut short")
    try:
        function = _open_library(code)[ENTRY_SYMBOL]
    except (OSError, AttributeError) as e:
        raise Refused(f"{library} cannot be opened ({str(e)[:200]})") from None
    function.restype, function.argtypes = ctypes.c_int, [ctypes.c_void_p] * ARGUMENTS
    return Entry(function, description["layout"], results, name)


def entry(name: str, compiled: Callable, args: tuple) -> Callable:
    """The function to call with `args`: the machine code of `name` when loaded and args fit it,
    else numba's `compiled()` (which imports numba)."""
    found = load(name)
    return found if found is not None and found.fits(args) else compiled()
