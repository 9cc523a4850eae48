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

Compiled-variant options (measured on the bench scenes; docs/architecture.md):
error_model="numpy" (x / 0 is inf or nan, as in numpy, instead of raising), no
reference counting (`_nrt=False`: kernels only read arrays the caller owns; counting
references to each array argument on every call made renders 2.3x slower), and
`inline=True` (numba inlines the function into its callers) for the ops and for the
functions that take the engine's tuples of arrays (the scene's geometry, the
materials): passing a tuple of arrays costs several machine words per array and call.
Math kernels are left to LLVM, which inlines the small ones itself; inlining them in
numba too only doubled the first compile (80 s instead of 36 s) for no speed.
"""

from __future__ import annotations

import contextlib
import dis
import functools
import hashlib
import importlib.util
import math
import os
import sys
import tempfile
import types

import numpy as np

ENABLED = os.environ.get("RTCLI_NUMBA", "1") != "0" and importlib.util.find_spec("numba") is not None
INF = math.inf


# --- where numba keeps the machine code it compiles (its on-disk cache) ---
CACHE_ENV = "RTCLI_CACHE_DIR"
PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))    # as numba sees the sources (not resolved)
COMPILED_DIRS = ("", "core", "shapes", "compiled")           # rtcli's folders whose functions numba compiles


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
        from numba.core import config
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


# --- the vocabulary, numpy variant (the names kernels import) ---
def select(mask, a, b):
    """a where mask holds, else b (a per-ray branch)."""
    return np.where(mask, a, b)


def not_(mask):
    """Logical not of a mask."""
    return np.logical_not(mask)


def narrow(t_near, t_far, t1, t2):
    """The interval [t_near, t_far] cut down to the span between t1 and t2 (either order); a NaN
    t1 or t2 (0 x inf: a ray lying in a slab's plane) leaves it as it is. The slab test's step."""
    return np.fmax(t_near, np.minimum(t1, t2)), np.fmin(t_far, np.maximum(t1, t2))


def to_int(x):
    """Truncation toward zero to int64 (x finite)."""
    return np.asarray(x).astype(np.int64)


def bits(x):
    """The 64 bits of a float as an unsigned integer (for hashing)."""
    return np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)


def u64(k):
    """An integer as uint64 (for hashing)."""
    return np.asarray(k).astype(np.uint64)


sqrt, floor = np.sqrt, np.floor
frexp, ldexp = np.frexp, np.ldexp             # x = m 2^e, m in [0.5, 1); m 2^e (e an integer)
minimum, maximum = np.minimum, np.maximum     # NaN in, NaN out
fmin, fmax = np.fmin, np.fmax                 # a NaN operand is ignored
copysign, isfinite, isnan = np.copysign, np.isfinite, np.isnan

VOCABULARY = ("select", "not_", "narrow", "to_int", "bits", "u64", "sqrt", "floor", "frexp", "ldexp", "minimum",
              "maximum", "fmin", "fmax", "copysign", "isfinite", "isnan")


# --- the scalar variant of each op (plain Python; numba compiles the same functions) ---
def _select(mask, a, b):
    return a if mask else b


def _not(mask):
    return not mask


def _narrow(t_near, t_far, t1, t2):
    if t1 != t1 or t2 != t2:
        return t_near, t_far
    if t1 > t2:
        t1, t2 = t2, t1
    return (t1 if t1 > t_near else t_near), (t2 if t2 < t_far else t_far)


def _to_int(x):
    return int(x)


def _minimum(a, b):
    if a != a:
        return a
    if b != b:
        return b
    return a if a <= b else b


def _maximum(a, b):
    if a != a:
        return a
    if b != b:
        return b
    return a if a >= b else b


def _fmin(a, b):
    if b != b:
        return a
    if a != a:
        return b
    return a if a <= b else b


def _fmax(a, b):
    if b != b:
        return a
    if a != a:
        return b
    return a if a >= b else b


def _u64(k):
    return np.uint64(k)


def _bits(x):
    return np.float64(x).view(np.uint64)


def _libm(f):
    """A C-library function on numpy float64 scalars, nan outside its domain (as in numba)."""
    def call(*args):
        try:
            return np.float64(f(*args))
        except ValueError:
            return np.float64(math.nan)
    call.__name__ = f.__name__
    return call


def _frexp(x):
    m, e = math.frexp(x)
    return np.float64(m), e


def _ldexp(m, e):
    try:
        return np.float64(math.ldexp(m, e))
    except OverflowError:
        return np.float64(math.copysign(math.inf, m))


_SCALAR = dict(select=_select, not_=_not, narrow=_narrow, to_int=_to_int, bits=_bits, u64=_u64, floor=np.floor,
               frexp=_frexp, ldexp=_ldexp, minimum=_minimum, maximum=_maximum, fmin=_fmin, fmax=_fmax,
               isfinite=math.isfinite, isnan=math.isnan, sqrt=_libm(math.sqrt), copysign=_libm(math.copysign))
_EXACT_LIBM = ("sqrt", "copysign", "frexp", "ldexp")   # exact on any CPU; numba's own (below)


def _numba_ops() -> dict:
    """The scalar ops as numba sees them: the same functions compiled; sqrt and copysign as LLVM's,
    frexp and ldexp from the bits."""
    from numba import njit
    from numba import types as nt
    from numba.extending import intrinsic

    @intrinsic
    def float_bits(typingctx, x):
        def codegen(context, builder, signature, args):
            from llvmlite import ir
            return builder.bitcast(args[0], ir.IntType(64))
        return nt.uint64(nt.float64), codegen

    @intrinsic
    def bits_float(typingctx, b):
        def codegen(context, builder, signature, args):
            from llvmlite import ir
            return builder.bitcast(args[0], ir.DoubleType())
        return nt.float64(nt.uint64), codegen

    def frexp(x):
        """math.frexp from the bits (numba's own calls a helper of its runtime)."""
        if x == 0 or x != x or x - x != 0:                   # zero, nan, inf
            return x, 0
        scale = 0
        if abs(x) < _TINY:                                   # subnormal: normal first
            x, scale = x * _TWO_54, 54
        b = float_bits(x)
        e = np.int64((b >> np.uint64(52)) & np.uint64(0x7FF))
        return bits_float((b & np.uint64(0x800FFFFFFFFFFFFF)) | np.uint64(0x3FE0000000000000)), e - 1022 - scale

    def ldexp(x, n):
        """math.ldexp by at most three products with powers of 2, only the last of them rounded (the
        others keep x normal), as the C library's scalbn does."""
        if n > 1023:
            x, n = x * _TWO_1023, n - 1023
            if n > 1023:
                x, n = x * _TWO_1023, min(n - 1023, 1023)
        elif n < -1022:
            x, n = x * _TWO_M969, n + 969
            if n < -1022:
                x, n = x * _TWO_M969, max(n + 969, -1022)
        return x * bits_float(np.uint64(n + 1023) << np.uint64(52))

    small = njit(inline="always", error_model="numpy", _nrt=False)
    ops = {name: small(f) for name, f in _SCALAR.items() if f.__module__ == __name__ and name not in _EXACT_LIBM}
    ops.update(sqrt=math.sqrt, floor=np.floor, frexp=small(frexp), ldexp=small(ldexp), copysign=math.copysign,
               isfinite=math.isfinite, isnan=math.isnan, bits=float_bits)
    return ops


_TINY, _TWO_54 = float.fromhex("0x1p-1022"), float.fromhex("0x1p54")
_TWO_1023, _TWO_M969 = float.fromhex("0x1p1023"), float.fromhex("0x1p-969")


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


def _variant(f, variant: str, bind: dict):
    if not is_kernel(f):
        raise TypeError(f"{f.__qualname__} is not a kernel")
    key = (f, variant, tuple(sorted((k, id(v)) for k, v in bind.items())))
    if key in _made:
        return _made[key]
    if variant not in _ops:
        _ops[variant] = _numba_ops() if variant == "compiled" else dict(_SCALAR)
    scope = dict(f.__globals__)
    scope.update(_ops[variant])
    made = types.FunctionType(f.__code__, scope, f.__name__, f.__defaults__, f.__closure__)
    made.__qualname__ = f.__qualname__ + _suffix(bind)
    made.__module__, made.__doc__ = f.__module__, f.__doc__
    if variant == "compiled":
        made = _numba(made, f.__kernel__)
    _made[key] = made                    # before the callees: a kernel may call itself through bind
    for name in f.__code__.co_names:
        value = bind[name] if name in bind else f.__globals__.get(name)
        if name in bind and not is_kernel(value):
            scope[name] = value
        elif is_kernel(value):
            scope[name] = _variant(value, variant, {})
        elif isinstance(value, types.ModuleType) and value not in (np, math):
            raise TypeError(f"kernel {f.__qualname__} calls through module {value.__name__}: "
                            "import the kernels it calls by name")
    return made


def _suffix(bind: dict) -> str:
    """A short name for what is bound, the same in every run (numba names its cache files by it)."""
    if not bind:
        return ""
    name = lambda v: getattr(getattr(v, "py_func", v), "__qualname__", None) or repr(v)
    what = ",".join(f"{k}={name(v)}" for k, v in sorted(bind.items()))
    return "_" + hashlib.sha1(what.encode()).hexdigest()[:12]


def _numba(f, how: Kernel):
    _start_numba()
    from numba import njit
    where = cache_location()
    options = dict(cache=where.enabled, error_model="numpy")
    if not how.entry:
        options["_nrt"] = False
    if how.inline:
        options["inline"] = "always"
    with where.applied():
        return njit(**options)(f)


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


_ALLOWED = [globals()[name] for name in VOCABULARY]


def variants_made() -> list:
    """(qualname, variant) of every variant made so far (for tests and the cache guard)."""
    return [(f.__qualname__, v) for (f, v, _) in _made]
