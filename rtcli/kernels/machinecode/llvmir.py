"""numba's optimised module read as text (LLVM IR) (rtcli/kernels/machinecode).

`parse_module` gives its functions as blocks of instructions with their successors and
predecessors, the external symbols it declares and the functions global variables name;
flow.py follows the paths through them. `foreign_symbols` lists the external functions and
variables of numba's runtime and helpers and of Python's C API (FOREIGN) that the library
defines as stubs (writing.wrapper_c), and `readable` turns a numba symbol back into the
Python name a refusal shows.
"""

from __future__ import annotations

import re

FOREIGN = ("NRT_", "numba_", "Py", "_Py")   # numba's runtime and helpers, Python's C API: their symbols' prefixes

NAME = r'(?:"(?:[^"\\]|\\.)*"|[-\w$.]+)'
REF = re.compile(r"@(" + NAME + r")")
CALL = re.compile(r"\bcall\b.*?([@%]" + NAME + r")\(")
ASSIGN = re.compile(r"^%(" + NAME + r") = (.*)$")
_DEFINE = re.compile(r"^define\b[^@]*@(" + NAME + r")\((.*)$")
_DECLARE = re.compile(r"^declare\b[^@]*@(" + NAME + r")\(")
_EXTERNAL = re.compile(r"^@(" + NAME + r") = (?:\w+ )*external\b")
_GLOBAL = re.compile(r"^@(" + NAME + r") = ")
_LABEL = re.compile(r"^(" + NAME + r"):")
_TARGET = re.compile(r"label %(" + NAME + r")")
_RANGE = re.compile(r"\brange\(i32 (-?\d+), (-?\d+)\)")


def unquote(name: str) -> str:
    """A name as LLVM prints it ("quoted" when it holds other characters) as the name itself."""
    return name[1:-1] if name.startswith('"') else name


class Function:
    """A function of the module as its text gives it: blocks (label -> instructions) in order."""

    def __init__(self, name: str, header: str):
        self.name, self.blocks = name, {}
        signature = header[:header.index("@")]
        self.status = re.search(r"\bi32\s*$", signature) is not None and "%excinfo" in header
        bounds = _RANGE.search(signature)             # LLVM's proof of the statuses it returns
        self.never_none = bounds is not None and not _within(int(bounds[1]), int(bounds[2]), -2)

    def finish(self) -> None:
        self.values = {unquote(m[1]): m[2] for code in self.blocks.values() for line in code
                       if (m := ASSIGN.match(line))}
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
    return list(dict.fromkeys(unquote(t) for t in _TARGET.findall(last)))


def parse_module(text: str) -> tuple[dict, set, set]:
    """The module's defined functions ({name: Function}), its external symbols, and the
    functions global variables' initialisers name (called from anywhere: roots)."""
    functions, external, rooted, current, block = {}, set(), set(), None, None
    for line in text.splitlines():
        if current is None:
            if m := _DEFINE.match(line):
                current, block = Function(unquote(m[1]), line), None
                functions[current.name] = current
            elif m := _DECLARE.match(line) or _EXTERNAL.match(line):
                external.add(unquote(m[1]))
            elif m := _GLOBAL.match(line):
                rooted.update(unquote(r) for r in REF.findall(line[m.end():]))
            continue
        if line.startswith("}"):
            current.finish()
            current = None
            continue
        code = line.split(";")[0].strip() if not line.lstrip().startswith(";") else ""
        if not code:
            continue
        if not line[0].isspace() and (m := _LABEL.match(line)):
            block = current.blocks[unquote(m[1])] = []
        elif block is None:
            block = current.blocks[""] = [code]
        elif block and block[-1].startswith("switch") and "]" not in block[-1]:
            block[-1] += " " + code               # a switch's cases, one a line
        else:
            block.append(code)
    return functions, external, rooted & set(functions)


def foreign_symbols(text: str) -> tuple[list[str], list[str]]:
    """The module's external functions and variables of numba's runtime and helpers and of
    Python's C API (FOREIGN): the library defines them as stubs (writing.wrapper_c)."""
    functions, variables = [], []
    for line in text.splitlines():
        m = _DECLARE.match(line) or _EXTERNAL.match(line)
        if m and unquote(m[1]).startswith(FOREIGN):
            name = unquote(m[1])
            if not re.fullmatch(r"[A-Za-z_]\w*", name):
                raise ValueError(f"cannot link a stub for {name!r}")
            (functions if line.startswith("declare") else variables).append(name)
    return sorted(set(functions)), sorted(set(variables))


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
