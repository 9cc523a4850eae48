"""The documents say what the code does: every shape of the registry has its row in the scene format."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from rtcli.shapes import SHAPES

ROOT = Path(__file__).resolve().parents[2]


def shape_rows() -> set:
    """The first cells of the shape table in docs/scene-format.md (its `| shape | parameters |` table)."""
    text = (ROOT / "docs" / "scene-format.md").read_text()
    table = text[text.index("| shape | parameters"):]
    table = table[:table.index("\n\n")]
    return {m.group(1) for m in re.finditer(r"^\| ([a-z_]+) \|", table, flags=re.M)} - {"shape"}


def test_every_registered_shape_has_a_row_in_the_scene_format():
    assert set(SHAPES) - shape_rows() == set()


def test_the_scene_format_lists_no_shape_that_is_not_registered():
    assert shape_rows() - set(SHAPES) == {"csg", "group"}


def test_the_architecture_document_shows_every_module():
    """Its layout lists each subpackage and each module (a file's name, or its stem in a list)."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    layout = text[text.index("```\nrtcli/"):]
    layout = layout[:layout.index("```", 4)]
    for path in sorted((ROOT / "rtcli").rglob("*.py")):
        if path.name not in ("__init__.py", "__main__.py"):
            assert path.name in layout or f" {path.stem} " in layout or f"({path.stem}" in layout, path
    for package in (p.parent for p in (ROOT / "rtcli").glob("*/__init__.py")):
        assert f"{package.name}/" in layout, package


def row_tables() -> list[tuple[str, str, list[str]]]:
    """(row, module path, columns) of each row of architecture.md's table of rows read by name."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    table = text[text.index("| row | defined in | columns |"):]
    rows = []
    for line in table.splitlines()[2:]:
        if not line.startswith("|"):
            break
        name, where, columns = (cell.strip() for cell in line.strip("|").split("|"))
        rows.append((name, where, re.findall(r"`([A-Z][A-Z0-9_]*)`", columns)))
    return rows


def column_statements(path: Path) -> list[set[str]]:
    """The names each module-level assignment of integer constants defines, one set a statement."""
    found = []
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
            names = [e.id for e in target.elts] if isinstance(target, ast.Tuple) else \
                [target.id] if isinstance(target, ast.Name) else []
            if names and all(n.isupper() for n in names):
                found.append(set(names))
    return found


def row_problems(rows, root: Path) -> list[str]:
    """What in the rows (row, module path under root, columns) differs from the code: a column
    listed that the module does not define, or one its assignment defines that no row of that
    module lists (the ints KIND and MATERIAL are shared by objects and csg leaves)."""
    problems = []
    for name, where, columns in rows:
        if not where.endswith(".py"):
            continue
        statements = column_statements(root / where)
        missing = set(columns) - set().union(*statements)
        problems += [f"{name}: {c} is not defined in {where}" for c in sorted(missing)]
        same_module = set().union(*(set(c) for _, w, c in rows if w == where))
        for names in (s for s in statements if s & set(columns)):
            problems += [f"{name}: {c} of {where} is not listed" for c in sorted(names - same_module)]
    return problems


def test_the_row_tables_of_the_architecture_document_are_the_codes():
    rows = row_tables()
    assert {"frame", "light", "camera", "csg leaf", "triangle (pool)"} <= {name for name, _, _ in rows}
    assert row_problems(rows, ROOT / "rtcli") == []


def test_a_row_that_misses_or_invents_a_column_is_caught(tmp_path):
    """The check above can fail: a row listing 2 of a statement's 3 columns, and one naming a column
    its module lacks."""
    (tmp_path / "m.py").write_text("(A, B,\n C) = 0, 1, 2\nWIDTH = 3\n")
    assert row_problems([("r", "m.py", ["A", "B"])], tmp_path) == ["r: C of m.py is not listed"]
    assert row_problems([("r", "m.py", ["A", "B", "C", "D"])], tmp_path) == ["r: D is not defined in m.py"]
    assert row_problems([("r", "m.py", ["A", "B", "C"])], tmp_path) == []
