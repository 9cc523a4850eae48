"""The vocabulary kernels are written in (rtcli/kernels/variants.py): the numpy variant of each op,
which kernels import by name, and its scalar counterparts, plain Python and as numba compiles them.
Every op is one IEEE defines to the last bit, so the variants agree to the last bit on every CPU."""

from __future__ import annotations

import math

import numpy as np

INF = math.inf


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


SCALAR = dict(select=_select, not_=_not, narrow=_narrow, to_int=_to_int, bits=_bits, u64=_u64, floor=np.floor,
               frexp=_frexp, ldexp=_ldexp, minimum=_minimum, maximum=_maximum, fmin=_fmin, fmax=_fmax,
               isfinite=math.isfinite, isnan=math.isnan, sqrt=_libm(math.sqrt), copysign=_libm(math.copysign))
_EXACT_LIBM = ("sqrt", "copysign", "frexp", "ldexp")   # exact on any CPU; numba's own (below)


def numba_ops() -> dict:
    """The scalar ops as numba sees them: the same functions compiled; sqrt and copysign as LLVM's,
    frexp and ldexp from the bits."""
    from numba import njit  # numba, optional (the fast extra): only the compiled variant needs it
    from numba import types as nt
    from numba.extending import intrinsic

    @intrinsic
    def float_bits(typingctx, x):
        def codegen(context, builder, signature, args):
            from llvmlite import ir  # numba's, when it generates code
            return builder.bitcast(args[0], ir.IntType(64))
        return nt.uint64(nt.float64), codegen

    @intrinsic
    def bits_float(typingctx, b):
        def codegen(context, builder, signature, args):
            from llvmlite import ir  # numba's, when it generates code
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

    small = njit(forceinline=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, error_model="numpy", _nrt=False)
    ops = {name: small(f) for name, f in SCALAR.items() if f.__module__ == __name__ and name not in _EXACT_LIBM}
    ops.update(sqrt=math.sqrt, floor=np.floor, frexp=small(frexp), ldexp=small(ldexp), copysign=math.copysign,
               isfinite=math.isfinite, isnan=math.isnan, bits=float_bits)
    return ops


_TINY, _TWO_54 = float.fromhex("0x1p-1022"), float.fromhex("0x1p54")
_TWO_1023, _TWO_M969 = float.fromhex("0x1p1023"), float.fromhex("0x1p-969")
