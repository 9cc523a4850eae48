"""numba's dispatcher as rtcli's compiled variants use it (imported only with numba): one machine
code per type of arguments, not one per constant.

numba types a constant argument (a walk's mode, NEAREST or ANY_CASTER; the bottom of a stack, 0)
as a literal of its value and compiles the callee, and everything it calls, once per value: the
scene's hit dispatch was compiled six times over. Here a constant is typed as its type (int64)
first, and as a literal only when the callee cannot be typed without it. Where the call is
inlined (forceinline, docs/architecture.md), LLVM still folds the constant.

A callee (a compiled variant only other kernels call, without Python's wrappers) gets no machine
code of its own: its callers' libraries hold it (`_callee_machine_code`). This reaches into
numba's code libraries (`numba.core.codegen`); with a numba whose internals differ it is left out,
and numba generates the code as usual.
"""

from __future__ import annotations

import llvmlite.binding as ll
from numba.core import errors
from numba.core import types as nt
from numba.core.codegen import JITCodeLibrary
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


CALLEE = ".callee"          # how a callee's name ends (variants._variant): numba names its code library so


def _callee_machine_code(finalize):
    """numba's last step of a code library (`_finalize_final_module`: the module to the JIT, which
    generates its machine code), for a callee's library: the JIT gets a copy of the module whose
    functions are `available_externally`, so it generates none of them, while callers link in the
    module itself. No Python calls a callee (it has no wrapper), and every caller inlines or compiles
    what it calls in its own library, so that machine code was made for nothing: 7.2 s of LLVM's
    time in a cold compile of the render engine, 3.0 s without it."""
    outside = (ll.Linkage.external, ll.Linkage.linkonce_odr)

    def finalize_callee(self):
        if not self.name.endswith(CALLEE):
            return finalize(self)
        kept = self._final_module
        self._final_module = kept.clone()
        for function in self._final_module.functions:
            if not function.is_declaration and function.linkage in outside:
                function.linkage = ll.Linkage.available_externally
        try:
            return finalize(self)
        finally:
            self._final_module = kept
    return finalize_callee


def _callee_optimisation(optimise):
    """numba's optimisation of a code library's module with its callees linked in (O3's module
    passes), for a callee's library: only numba's cheap pass (the inliner, which alwaysinline needs).
    The module is linked into each caller and optimised there with O3 again, with the callee inlined
    or beside it; the integrator's library, which is not a callee, gets the whole of O3 at the end."""
    def optimise_callee(self):
        if not self.name.endswith(CALLEE):
            return optimise(self)
        codegen = self._codegen
        passes, builder = codegen._module_pass_manager(loop_vectorize=codegen._loopvect, slp_vectorize=False,
                                                       opt=codegen._opt_level, cost="cheap")
        passes.run(self._final_module, builder)
    return optimise_callee


def _install() -> None:
    for name, change in (("_finalize_final_module", _callee_machine_code),
                         ("_optimize_final_module", _callee_optimisation)):
        original = getattr(JITCodeLibrary, name, None)
        if original is not None and not getattr(original, "rtcli", False):
            setattr(JITCodeLibrary, name, change(original))
            getattr(JITCodeLibrary, name).rtcli = True


_install()
