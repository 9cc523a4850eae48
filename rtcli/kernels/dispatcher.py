"""numba's dispatcher as rtcli's compiled variants use it (imported only with numba): one machine
code per type of arguments, not one per constant.

numba types a constant argument (a walk's mode, NEAREST or ANY_CASTER; the bottom of a stack, 0)
as a literal of its value and compiles the callee, and everything it calls, once per value: the
scene's hit dispatch was compiled six times over. Here a constant is typed as its type (int64)
first, and as a literal only when the callee cannot be typed without it. Where the call is
inlined (forceinline, docs/architecture.md), LLVM still folds the constant.
"""

from __future__ import annotations

from numba.core import errors
from numba.core import types as nt
from numba.core.registry import CPUDispatcher


class Dispatcher(CPUDispatcher):
    def get_call_template(self, args, kws):
        plain = tuple(nt.unliteral(a) for a in args), {k: nt.unliteral(v) for k, v in kws.items()}
        if plain == (tuple(args), kws):
            return super().get_call_template(args, kws)
        try:
            return super().get_call_template(*plain)
        except errors.TypingError:              # a kernel that needs the constant to be typed
            return super().get_call_template(args, kws)
