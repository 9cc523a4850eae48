"""The documents say what the code does: every shape of the registry has its row in the scene format."""

from __future__ import annotations

import re
from pathlib import Path

from rtcli.shapes import SHAPES

ROOT = Path(__file__).resolve().parent.parent


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
