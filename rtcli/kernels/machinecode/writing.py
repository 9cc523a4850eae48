"""Writing an entry's machine code file (rtcli/kernels/machinecode; needs numba).

`make` wraps numba's compiled entry in a cfunc that rebuilds its arguments (arguments.py),
takes numba's optimised module of it, refuses it when a call could reach numba's helpers on a
path that raises nothing (flow.helper_calls), emits it as position-independent object code for
this CPU and links it with a small C file (`wrapper_c`: the entry rtcli calls and the helpers'
stubs) by the C compiler, `cc`. Writing is atomic: the library's name holds a hash of its
bytes, and the description (.json), replaced last, names it and records its SHA-256 and this
process's key (places.py): `_commit`.
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from rtcli.kernels.machinecode import entries, places  # ENABLED and folder() read when called
from rtcli.kernels.machinecode.arguments import classes, dtypes, layout, pointer_intrinsic, wrapper_source
from rtcli.kernels.machinecode.flow import helper_calls
from rtcli.kernels.machinecode.llvmir import foreign_symbols, readable
from rtcli.kernels.machinecode.places import ENTRY_SYMBOL, description_file, key
from rtcli.kernels.machinecode.trust import Refused, trusted_folder

BODY_SYMBOL = "rtcli_body"              # numba's cfunc, renamed in the library, hidden


def make(name: str, dispatcher, args: tuple, results: int = 0) -> str | None:
    """Write the machine code of numba's `dispatcher` (called with `args` once already) wrapped for
    calls with arguments of args' layout; None when written, else why not. It reaches into
    numba's code library for the optimised module, so a failure only means there is no file."""
    place, cc = places.folder(), compiler()
    if not places.ENABLED:
        return "RTCLI_MACHINE_CODE=0"
    if place is None:
        return "no cache folder"
    if cc is None:
        return "no C compiler (cc) to link them"
    try:
        os.close(trusted_folder(place))
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
    import llvmlite.binding as ll  # start-up: llvmlite and numba only when a file is made
    from numba import carray, cfunc  # start-up: as above
    from numba import types as nt  # start-up: as above
    source, tuples = wrapper_source([(layout(a), classes(a)) for a in args], results)
    scope = {"carray": carray, "pointer": pointer_intrinsic(), "body": dispatcher}
    scope.update({f"D{np.dtype(d).name}": np.dtype(d).type for d in dtypes([layout(a) for a in args])})
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
                                   "key": key()}))
    os.chmod(written, 0o644)
    os.replace(written, description_file(name, place))
    for old in place.glob(f"rtcli-{name}-*.so"):
        if old != library:
            old.unlink(missing_ok=True)
    entries.forget(name)


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


def compiler() -> list[str] | None:
    """The C compiler command that links the shared libraries: $CC (may hold options), else cc,
    gcc or clang."""
    given = shlex.split(os.environ.get("CC", ""))
    if given:
        return [shutil.which(given[0]) or given[0], *given[1:]]
    found = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    return [found] if found else None
