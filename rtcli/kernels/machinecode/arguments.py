"""What an entry's arguments look like, and how a call passes them (rtcli/kernels/machinecode).

The arguments of an entry are arrays, numbers, bools and namedtuples of those (the compiled
engine's Geometry and Looks). Their `layout` (each leaf's kind, an array's dtype and number
of dimensions, a namedtuple's fields) is fixed when the file is made. A call `flatten`s them
into a list of words and a list of floats: each array as its address and shape
(C-contiguous, aligned arrays only: `passable`), each int and bool as a word and each float
as a float. `wrapper_source` writes the numba cfunc that rebuilds them on the other side
(carray over `pointer`, the namedtuples' classes called again) and calls the entry.
"""

from __future__ import annotations

import numpy as np


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


def classes(value):
    """The namedtuple classes of an argument, shaped as its layout: (class, [fields']) or None."""
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return type(value), [classes(v) for v in value]
    return None


def dtypes(layouts: list):
    """The dtypes of the arrays in these layouts (the names D<dtype> wrapper_source uses)."""
    for lay in layouts:
        if lay[0] == "a":
            yield lay[1]
        elif lay[0] == "t":
            yield from dtypes(lay[1])


def pointer_intrinsic():
    """numba intrinsic pointer(address, dtype): the int64 address as a pointer to dtype."""
    from numba import types as nt  # start-up: numba only when a file is made
    from numba.extending import intrinsic  # start-up: as above

    @intrinsic
    def pointer(typingctx, address, dtype):
        to = nt.CPointer(dtype.dtype)

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(to))
        return to(nt.int64, dtype), codegen
    return pointer
