"""Which of numba's helpers a call can reach, read from the module's LLVM IR (rtcli/kernels/machinecode).

numba's functions return a status (numba/core/callconv.py): 0, or -2 for None, when they
return; any other value when they raise, the exception described in *excinfo. A helper call
lies on a path that raises when its block returns an error status whatever happens next
("doomed"; a call's status past the branch that found it failed counts as one), or, in the C
function (which returns no status), when it is reached only past such a branch, to report
it. A function whose failure its caller does not pass on (as numba's try/except would) has
no such path: all of it may run on a call that returns. Nothing else may touch numba's
runtime or Python: `helper_calls` lists what does (docs/architecture.md, numba's helpers),
and writing.make refuses a module where it finds one.
"""

from __future__ import annotations

import re

from rtcli.kernels.machinecode.llvmir import ASSIGN, CALL, FOREIGN, NAME, REF, Function, parse_module, unquote

_BRANCH = re.compile(r"^br i1 %(" + NAME + r"), label %(" + NAME + r"), label %(" + NAME + r")")
_COMPARE = re.compile(r"^icmp (eq|ne) i32 (%" + NAME + r"|-?\d+), (%" + NAME + r"|-?\d+)$")
_SWITCH = re.compile(r"^switch i32 %(" + NAME + r"), label %(" + NAME + r") \[(.*)\]")
_CASE = re.compile(r"i32 (-?\d+), label %(" + NAME + r")")
_RETURN = re.compile(r"^ret i32 %(" + NAME + r")$")
_INCOMING = re.compile(r"\[\s*([^,\]]+?),\s*%(" + NAME + r")\s*\]")
RETURNED = (0, -2)                      # the statuses of a function that returned (not raised)
ALLOWED = {("NRT_decref", "NRT_MemInfo_call_dtor")}
# NRT_decref (numba's own, in the module) calls the destructor when a count falls to zero,
# and only an allocation (NRT_MemInfo_alloc..., which helper_calls finds) makes a count: the
# arrays an entry gets come from carray, with none (their meminfo is null).


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
                called = CALL.search(line)
                pointers = pointers or (called is not None and called[1][0] == "%")
                for ref in (unquote(r) for r in REF.findall(line)):
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
                called = CALL.search(line)
                refs = [unquote(r) for r in REF.findall(line)]
                if called and called[1][0] == "@" and unquote(called[1][1:]) == name:
                    refs.remove(name)
                if name in refs:
                    return True
    return False


def _constant_error(value: str) -> bool:
    try:
        return int(value) not in RETURNED
    except ValueError:
        return False


class _Flow:
    """Where a function raises: the branches a failed call's status takes (`edges`), the blocks
    reached only through them with the statuses known there to be errors (`failed`), and the
    blocks that return an error status whatever happens next (`doomed`)."""

    def __init__(self, f: Function, functions: dict):
        self.f, self.functions = f, functions
        self.edges = self._failure_edges()
        self.failed = self._failed()
        self.doomed = self._doomed()

    def status_callee(self, line: str) -> Function | None:
        """The function returning a status (numba's) that `line` calls directly, if any."""
        called = CALL.search(line)
        g = self.functions.get(unquote(called[1][1:])) if called and called[1][0] == "@" else None
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
        compare = _COMPARE.match(self.f.values.get(unquote(branch[1]), "")) if branch else None
        if not compare or "0" not in (compare[2], compare[3]) or branch[2] == branch[3]:
            return []
        status = unquote((compare[3] if compare[2] == "0" else compare[2])[1:])
        callee = self.status_callee(self.f.values.get(status, ""))
        if callee is None or not callee.never_none:
            return []
        return [(status, unquote(branch[3] if compare[1] == "eq" else branch[2]))]

    def _switch_failures(self, last: str) -> list:
        switch = _SWITCH.match(last)
        callee = self.status_callee(self.f.values.get(unquote(switch[1]), "")) if switch else None
        if callee is None:
            return []
        cases = [(int(v), unquote(t)) for v, t in _CASE.findall(switch[3])]
        returned = {t for v, t in cases if v in RETURNED}
        failures = [t for v, t in cases if v not in RETURNED]
        values = {v for v, _ in cases}
        if 0 in values and (-2 in values or callee.never_none):
            failures.append(unquote(switch[2]))
        return [(unquote(switch[1]), t) for t in dict.fromkeys(failures) if t not in returned]

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
        return _constant_error(value) or (value.startswith("%") and unquote(value[1:]) in self.failed.get(b, ()))

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
        value, phi = "%" + returned[1], self.f.values.get(unquote(returned[1]), "")
        if phi.startswith("phi ") and any(line.startswith(value + " = phi ") for line in code):
            value = {unquote(block): v.strip() for v, block in _INCOMING.findall(phi)}.get(b, "0")
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
                assigned = ASSIGN.match(line)
                if callee is not None and (assigned is None or not self._passes_on(unquote(assigned[1]), b)):
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
            return self._returned(b, unquote(last[len("br label %"):])) == f"%{status}"
        return last == f"ret i32 %{status}"
