"""The BVH build's compiled variant (core/bvh_build.py's `levels`), run from its machine code
file when there is one for this process (no numba needed), else by numba: 100,000 triangles'
tree in a few hundredths of a second. The engine choice (rendering/engine.py) hands `runner()`
to whatever builds trees for a render; core/ never picks it itself."""

from __future__ import annotations

import sys

from rtcli.core.bvh_build import levels, levels_build
from rtcli.kernels import machinecode, variants

LEVELS = "levels"                 # the machine code file of `levels` (rtcli/kernels/machinecode)


def _compiled_levels():
    return variants.compiled(levels)


def run(*args):
    """`levels(*args)` by its machine code file when it fits the arguments, else by numba."""
    return machinecode.entry(LEVELS, _compiled_levels, args)(*args)


def runner():
    """The compiled `levels`, when it starts at once: its machine code file is at hand, or numba is
    loaded already (a render loads it for its walks anyway); None otherwise (the numpy build), so
    that checking a scene never waits for numba to start."""
    if variants.ENABLED and ("numba" in sys.modules or machinecode.load(LEVELS) is not None):
        return run
    return None


def build(lo, hi, leaf_size: int, bins: int, variant=None):
    """The tree of `levels` run by its compiled variant (or by `variant`, say variants.python(levels))."""
    return levels_build(lo, hi, leaf_size, bins, variant or run)
