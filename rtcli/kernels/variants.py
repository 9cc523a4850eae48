"""One source for the physics, several variants: a kernel is written once and run on
numpy arrays (the wavefront engine) or one ray at a time (the compiled engine).

A kernel is a plain function whose per-ray inputs are floats or (n,) arrays, written
with a small vocabulary (this module): arithmetic and comparisons, `&` `|` and
`not_` on masks, `select(mask, a, b)` where code would branch on a per-ray value,
and the math functions below. An `if` is allowed only on values that are the same
for every ray of a call (a shape's parameters, a light's kind). Kernels call other
kernels by the names they import, and return tuples of components: (x, y, z), not
(n, 3) arrays. This is how Mitsuba 3 writes `Sphere<Float, Spectrum>` once for its
scalar and vectorized variants, and how pbrt-v4 shares shapes between its CPU and
GPU integrators.

The variants of a kernel `f`:
- `f` itself, as imported: the numpy variant. Its ops are numpy's ufuncs, so it runs
  on whole arrays (and on numpy scalars).
- `python(f)`: plain Python on floats, one ray at a time. The easiest to step
  through in a debugger, and needs no numba.
- `compiled(f)`: the same scalar code compiled by numba (extra `fast`), as the
  compiled engine calls it.

Each variant is the same code object with other globals: the ops of this module
and every kernel it calls are swapped for their counterparts, so no formula is
written twice. `@per_ray` marks code that only makes sense for one ray (a BVH
walk, the integrator loop): it has python and compiled variants but no numpy one.

Bit for bit: the scalar variants do the numpy variant's floating-point operations in
the same order, and the vocabulary holds only operations that IEEE defines to the last
bit (arithmetic, sqrt, floor, frexp, ldexp, comparisons), so they agree to the last bit,
and so do CPUs of every kind. Kernels take no math from numpy or the C library:
numpy's x ** y, arccos, arcsin, arctan2 and cbrt come from Intel's SVML on AVX-512 CPUs
and differ from the C library's in the last bit. rtcli's own elementary functions,
kernels themselves, are in rtcli/core/elementary.py, and `foreign_math` finds any
other (a test checks every kernel).

Compiled-variant options (measured; docs/architecture.md, "How the compiled variants are
built"): error_model="numpy" (x / 0 is inf or nan, as in numpy, instead of raising), no
reference counting (`_nrt=False`: kernels only read arrays the caller owns; counting
references to each array argument on every call made renders 2.3x slower). The ops and the
functions marked `inline=True` (those that take the engine's tuples of arrays: passing a
tuple of arrays costs several machine words per array and call) are inlined by LLVM into
their callers (numba's `forceinline`, LLVM's alwaysinline), not by numba (its
inline="always" types the callee again at every call site: the integrator's first compile
took twice as long). A kernel called by other kernels is compiled once as a callee, without
the wrappers that let Python call it; and once per type of its arguments, not per constant
(rtcli/kernels/dispatcher.py): the scene's hit dispatch was compiled six times over.
"""

from __future__ import annotations

import dis
import functools
import hashlib
import importlib.util
import math
import os
import sys
import types

import numpy as np

from rtcli.kernels import vocabulary
from rtcli.kernels.numba_cache import cache_location
from rtcli.kernels.vocabulary import (  # noqa: F401  (the names kernels import, with the decorators below)
    INF, VOCABULARY, bits, copysign, floor, fmax, fmin, frexp, isfinite, isnan, ldexp, maximum, minimum, narrow,
    not_, select, sqrt, to_int, u64)

ENABLED = os.environ.get("RTCLI_NUMBA", "1") != "0" and importlib.util.find_spec("numba") is not None


# --- kernels and their variants ---
class Kernel:
    """How a kernel is compiled: inline into its callers, or an entry that allocates."""

    def __init__(self, per_ray: bool, inline: bool, entry: bool):
        self.per_ray, self.inline, self.entry = per_ray, inline, entry


def _mark(f, per_ray: bool, inline: bool = False, entry: bool = False):
    f.__kernel__ = Kernel(per_ray, inline, entry)
    return f


def kernel(f=None, *, inline: bool = False):
    """Mark a function written in the vocabulary: numpy, python and compiled variants."""
    if f is None:
        return lambda g: _mark(g, False, inline)
    return _mark(f, False, inline)


def per_ray(f=None, *, inline: bool = False, entry: bool = False):
    """Mark scalar-only code (loops over a BVH, the integrator): python and compiled variants.
    `entry`: called from Python with arrays it may allocate (numba's reference counting on)."""
    if f is None:
        return lambda g: _mark(g, True, inline, entry)
    return _mark(f, True, inline, entry)


def is_kernel(f) -> bool:
    return hasattr(f, "__kernel__")


_made: dict = {}
_ops: dict = {}


def python(f, **bind):
    """The plain-Python scalar variant of kernel f (its globals `bind` replaced, if given).

    It computes in numpy float64 scalars, so x / 0 is inf as in the other variants (warnings
    off), and calls the C library for the math, as numba does."""
    made = _variant(f, "python", bind)

    @functools.wraps(made)
    def call(*args):
        with np.errstate(all="ignore"):
            return made(*(np.float64(a) if type(a) is float else a for a in args))
    return call


def compiled(f, **bind):
    """The numba-compiled scalar variant of kernel f. `bind` replaces globals of f: one
    source, specialised (say, a BVH walk for triangles or for scene objects)."""
    return _variant(f, "compiled", bind)


_origins: dict = {}                      # id of a compiled variant -> (kernel, bind): for its callee twin


def _variant(f, variant: str, bind: dict, callee: bool = False):
    """The variant of f; `callee`: the compiled one as other kernels call it, without the code that
    lets Python call it (numba's wrappers), which would be compiled for nothing."""
    if not is_kernel(f):
        raise TypeError(f"{f.__qualname__} is not a kernel")
    callee = callee and variant == "compiled"
    key = (f, variant, tuple(sorted((k, id(v)) for k, v in bind.items())), callee)
    if key in _made:
        return _made[key]
    if variant not in _ops:
        _ops[variant] = vocabulary.numba_ops() if variant == "compiled" else dict(vocabulary.SCALAR)
    scope = dict(f.__globals__)
    scope.update(_ops[variant])
    made = types.FunctionType(f.__code__, scope, f.__name__, f.__defaults__, f.__closure__)
    made.__qualname__ = f.__qualname__ + _suffix(bind) + (".callee" if callee else "")
    made.__module__, made.__doc__ = f.__module__, f.__doc__
    if variant == "compiled":
        made = _numba(made, f.__kernel__, callee)
        _origins[id(made)] = (f, bind)
    _made[key] = made                    # before the callees: a kernel may call itself through bind
    for name in f.__code__.co_names:
        value = bind[name] if name in bind else f.__globals__.get(name)
        if name in bind and not is_kernel(value):
            scope[name] = _callee_of(value, variant)
        elif is_kernel(value):
            scope[name] = _variant(value, variant, {}, callee=True)
        elif isinstance(value, types.ModuleType) and value not in (np, math):
            raise TypeError(f"kernel {f.__qualname__} calls through module {value.__name__}: "
                            "import the kernels it calls by name")
    return made


def _callee_of(value, variant: str):
    """A bound value as a kernel calls it: a compiled variant's callee twin, else the value."""
    if variant == "compiled" and id(value) in _origins and value is _made.get(_key_of(value)):
        f, bind = _origins[id(value)]
        return _variant(f, variant, bind, callee=True)
    return value


def _key_of(value):
    f, bind = _origins[id(value)]
    return (f, "compiled", tuple(sorted((k, id(v)) for k, v in bind.items())), False)


def _suffix(bind: dict) -> str:
    """A short name for what is bound, the same in every run (numba names its cache files by it)."""
    if not bind:
        return ""
    name = lambda v: getattr(getattr(v, "py_func", v), "__qualname__", None) or repr(v)
    what = ",".join(f"{k}={name(v)}" for k, v in sorted(bind.items()))
    return "_" + hashlib.sha1(what.encode()).hexdigest()[:12]


def _numba(f, how: Kernel, callee: bool = False):
    _start_numba()
    from rtcli.kernels.dispatcher import Dispatcher  # numba, optional (the fast extra): only when compiling
    where = cache_location()
    options = dict(nopython=True, error_model="numpy", forceinline=how.inline)
    if not how.entry:
        options["_nrt"] = False
    if callee:
        options.update(no_cpython_wrapper=True, no_cfunc_wrapper=True)
    with where.applied():
        made = Dispatcher(py_func=f, locals={}, targetoptions=options)
        if where.enabled:
            made.enable_caching()
    return made


_started = False


def _start_numba() -> None:
    """Import numba's array functions with scipy's BLAS hidden, once. numba looks for a BLAS (for
    np.dot in compiled code) when that module is first imported, which imports scipy.linalg,
    about 0.1-0.2 s; rtcli's compiled code needs none, so numba goes on without it."""
    global _started
    if _started:
        return
    name = "scipy.linalg.cython_blas"
    hidden = name not in sys.modules
    if hidden:
        sys.modules[name] = None                         # the import fails at once
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if hidden and sys.modules.get(name, 0) is None:
            del sys.modules[name]
    _started = True


EXACT = frozenset(VOCABULARY)


def foreign_math(f, seen=None) -> set:
    """What f, or a kernel it calls, takes from numpy or the C library beyond the exact ops of the
    vocabulary: x ** y, or a function such as np.exp or math.atan2. Their numpy and C-library
    versions may differ in the last bit (numpy takes some from Intel's SVML on AVX-512 CPUs), so the
    variants could too; rtcli's own are in rtcli/core/elementary.py. Empty for every kernel (tested)."""
    seen = set() if seen is None else seen
    if f in seen:
        return set()
    seen.add(f)
    found, module = set(), None
    for i in dis.get_instructions(f):
        if i.opname == "BINARY_POWER" or (i.opname == "BINARY_OP" and i.argrepr in ("**", "**=")):
            found.add("**")
        elif i.opname in ("LOAD_ATTR", "LOAD_METHOD") and module is not None:
            attribute = getattr(module, i.argval, None)
            if callable(attribute) and not isinstance(attribute, type) and i.argval not in EXACT:
                found.add(f"{module.__name__}.{i.argval}")
        value = f.__globals__.get(i.argval) if i.opname == "LOAD_GLOBAL" else None
        module = value if value is np or value is math else None
        if is_kernel(value):
            found |= foreign_math(value, seen)
        elif isinstance(value, (np.ufunc, types.BuiltinFunctionType)) and not any(value is v for v in _ALLOWED):
            found.add(i.argval)
    return found


_ALLOWED = [getattr(vocabulary, name) for name in VOCABULARY]


def variants_made() -> list:
    """(qualname, variant) of every variant made so far (for tests and the cache guard)."""
    return [(f.__qualname__, v) for (f, v, _, _) in _made]

