"""The package's shape (docs/architecture.md, The layout): imports run one way, down the floors, with
no circle; core/ picks no engine and loads no machine code; the two engines import nothing of
each other; the top level keeps only a few modules every floor uses."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "rtcli"


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def imports_of(path: Path, known: set[str]) -> set[str]:
    """The rtcli modules a file imports, at module level or inside functions: `from a.b import c`
    counts as a.b.c when that is a module, else as a.b."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:         # rtcli writes no relative import
            found |= {f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in known else node.module
                      for a in node.names}
    return {m for m in found if m in known}


def graph() -> dict[str, set[str]]:
    known = set(modules())
    return {name: imports_of(path, known) - {name} for name, path in modules().items()}


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The import circles of a graph (Tarjan's strongly connected components of more than one)."""
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                found.append(sorted(part))
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def test_no_import_circle_at_module_level_or_inside_functions():
    assert circles(graph()) == []


def test_a_circle_is_found():
    """The check can fail: a -> b -> c -> a, beside an acyclic d -> a."""
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_imports_name_the_modules_they_reach(tmp_path):
    """`from rtcli.x import y` counts as the module rtcli.x.y when there is one, else as rtcli.x;
    imports inside functions count too."""
    source = tmp_path / "m.py"
    source.write_text("from rtcli.core.vec import dot\nfrom rtcli import cli\n"
                      "def f():\n    from rtcli.cluster import renders\n")
    assert imports_of(source, set(modules())) == {"rtcli.core.vec", "rtcli.cli", "rtcli.cluster.renders"}


@pytest.mark.parametrize("floor, forbidden", [
    ("rtcli.core", ("rtcli.shapes", "rtcli.wavefront", "rtcli.compiled", "rtcli.kernels.machinecode",
                    "rtcli.rendering")),
    ("rtcli.shapes", ("rtcli.wavefront", "rtcli.compiled", "rtcli.kernels.machinecode", "rtcli.rendering")),
    ("rtcli.wavefront", ("rtcli.compiled", "rtcli.kernels.machinecode", "rtcli.rendering")),
    ("rtcli.compiled", ("rtcli.wavefront", "rtcli.rendering")),
    ("rtcli.scenefile", ("rtcli.wavefront", "rtcli.compiled", "rtcli.rendering", "rtcli.api", "rtcli.cli")),
    ("rtcli.rendering", ("rtcli.api", "rtcli.cli", "rtcli.inspect", "rtcli.cluster", "rtcli.compare", "rtcli.preview")),
    ("rtcli.api", ("rtcli.cli", "rtcli.preview")),
])
def test_imports_run_down_the_floors(floor, forbidden):
    """core/ picks no engine and loads no machine code; the engines import nothing of each other
    (rendering/engine.py is the one place that knows both); nothing below the command line imports it."""
    bad = {(name, target) for name, targets in graph().items() if name == floor or name.startswith(floor + ".")
           for target in targets if any(target == f or target.startswith(f + ".") for f in forbidden)}
    assert bad == set()


def test_the_top_level_keeps_a_few_modules_every_floor_uses():
    flat = sorted(p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))
    assert len(flat) <= 4, flat


def too_long(path: Path, file_lines: int = 300, function_lines: int = 60) -> list[str]:
    """What in a file is longer than the layout allows: the file itself, or a function."""
    text = path.read_text()
    found = [f"{path.name}: {len(text.splitlines())} lines"] if len(text.splitlines()) > file_lines else []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            length = node.end_lineno - node.lineno + 1
            if length > function_lines:
                found.append(f"{path.name}:{node.lineno} {node.name}: {length} lines")
    return found


def test_no_file_over_300_lines_and_no_function_over_60():
    assert [item for path in modules().values() for item in too_long(path)] == []


def test_a_long_function_is_found(tmp_path):
    source = tmp_path / "m.py"
    source.write_text("def f():\n" + "    x = 1\n" * 60 + "\n\ndef g():\n    pass\n")
    assert too_long(source) == ["m.py:1 f: 61 lines"]
    assert too_long(source, file_lines=10) == ["m.py: 65 lines", "m.py:1 f: 61 lines"]


def unexplained_imports(path: Path) -> list[int]:
    """The lines of imports inside functions with no comment saying why they wait: a run of imports
    one after another needs one comment among them or on the line above."""
    text = path.read_text()
    lines, found = text.splitlines(), []
    for function in ast.walk(ast.parse(text)):
        if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for block in (getattr(n, field, None) for n in ast.walk(function) for field in ("body", "orelse", "finalbody")):
            run = []
            for statement in (block if isinstance(block, list) else []) + [None]:
                if isinstance(statement, (ast.Import, ast.ImportFrom)):
                    run.append(statement)
                    continue
                if run and not any(line.lstrip().startswith("#") or "  #" in line
                                   for line in lines[run[0].lineno - 2:run[-1].end_lineno]):
                    found.append(run[0].lineno)
                run = []
    return sorted(set(found))


def test_imports_inside_functions_say_why_they_wait():
    """Imports are at module level unless start-up time or an optional extra needs them to wait,
    and then a comment says so."""
    assert {name: lines for name, path in modules().items() if (lines := unexplained_imports(path))} == {}


def test_an_unexplained_import_is_found(tmp_path):
    source = tmp_path / "m.py"
    source.write_text("def f():\n    import json\n    import csv\n\n\ndef g():\n"
                      "    import json  # start-up\n    import csv\n    if x:\n        import zlib\n"
                      "    # start-up\n    import zlib\n    x = '#'\n    import csv\n")
    assert unexplained_imports(source) == [2, 10, 14]
