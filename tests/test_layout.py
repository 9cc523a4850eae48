"""The package's shape (docs/architecture.md, The layout): imports run one way, down the floors, with
no circle; core/ picks no engine and loads no machine code; the two engines import nothing of
each other; the top level keeps only a few modules every floor uses."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
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
    ("rtcli.core", ("rtcli.wavefront", "rtcli.compiled", "rtcli.kernels.machinecode", "rtcli.rendering")),
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
