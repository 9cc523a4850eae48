"""Safe YAML loading that remembers where every value came from.

Mappings load as `MapNode` (a dict) and sequences as `SeqNode` (a list); each
records its own location and those of its keys and items, so any value can be
reported as `file:line:col`. Anchors, aliases and merge keys (`<<`) work as in
PyYAML's safe loader; Python object tags are refused. `include:` files are
loaded first, relative to the including file's folder, each file once, with
cycle detection.

The tree is built straight from the parser's events (yamlevents.py), without
PyYAML's node graph, and locations are kept packed in one array per mapping or
list (nodes.py): a big scene costs little more than its values. Loading is bounded
(docs/scene-format.md, "Limits"): values nest at most MAX_DEPTH deep, aliases
(each counted as a copy of what it names) add at most ALIAS_BUDGET values, an
alias may not name a collection that contains it, and files are size-limited
regular files (limits.py, files.py).
"""

from __future__ import annotations

import os
import re

import yaml

from rtcli.errors import SceneError, Where, shown
from rtcli.scenefile import yamlbulk
from rtcli.scenefile.files import read_bytes, real_path
from rtcli.scenefile.limits import MAX_INCLUDE_DEPTH, MAX_SCENE_BYTES
from rtcli.scenefile.nodes import MapNode, SeqNode
from rtcli.scenefile.yamlevents import Builder, Loader

__all__ = ["MapNode", "SeqNode", "INCLUDABLE", "parse", "read_text", "load", "load_tree"]

INCLUDABLE = {"version", "include", "materials", "lights", "objects"}
_UNQUOTED_COLOR = re.compile(r"(?:^|[\s\[{,:-])(#[0-9a-fA-F]{6})\b")


def parse(text: str, display: str, folder: str = ".") -> MapNode:
    """Parse one YAML document whose top level must be a mapping; runs of spheres written one a
    line are read in bulk (yamlbulk.py), any error found again the usual way."""
    short, runs = yamlbulk.extract(text)
    if runs:
        try:
            tree = _parse(short, display, folder)
        except SceneError:
            tree = None
        if tree is not None and yamlbulk.place(tree, runs):
            return tree
    return _parse(text, display, folder)


def _parse(text: str, display: str, folder: str) -> MapNode:
    loader = Loader(text)
    try:
        tree = Builder(loader, display, folder, text).document()
    except yaml.MarkedYAMLError as e:
        raise _syntax_error(e, text, display) from None
    except yaml.reader.ReaderError as e:
        position = e.position
        if not isinstance(loader, yaml.SafeLoader):     # libyaml counts bytes of UTF-8
            position = len(text.encode("utf-8")[:position].decode("utf-8", errors="ignore"))
        raise SceneError(_where_in(text, display, position), "", "invalid YAML: "
                         f"{_character(e.character)} is not allowed (control characters cannot appear in YAML)"
                         ) from None
    except yaml.YAMLError as e:
        raise SceneError(display, "", f"invalid YAML: {' '.join(str(e).split())}") from None
    finally:
        loader.dispose()
    if tree is None:
        return MapNode.empty(Where(display, 1, 1), folder)
    if not isinstance(tree, MapNode):
        raise SceneError(Where(display, 1, 1), "", "a scene must be a mapping of keys")
    return tree


def _syntax_error(e: yaml.MarkedYAMLError, text: str, display: str) -> SceneError:
    mark = e.problem_mark or e.context_mark
    where = Where(display, mark.line + 1, mark.column + 1) if mark else display
    problem = " ".join(str(e.problem or e.context).split())
    if mark and _char_at(text, mark.line, mark.column) == "\t":
        problem = "tab characters cannot indent YAML (use spaces)"
    elif mark and (color := _commented_color(text, mark.line)):
        problem += f" (YAML reads the unquoted {color} as a comment: write it in quotes, \"{color}\")"
    return SceneError(where, "", f"invalid YAML: {problem}")


def _commented_color(text: str, line: int) -> str | None:
    """The first unquoted #rrggbb on the error's line or the line before (where a flow list such
    as `[#ff0000, #00ff00]` lost its end to the comment), or None."""
    lines = text.splitlines()
    for k in (line - 1, line):
        if 0 <= k < len(lines) and (found := _UNQUOTED_COLOR.search(lines[k])):
            return found.group(1)
    return None


def _character(c) -> str:
    code = ord(c) if isinstance(c, str) else int(c)
    return f"the character U+{code:04X}"


def _where_in(text: str, display: str, position: int) -> Where:
    """Line and column of character `position` of `text`."""
    line = text.count("\n", 0, position)
    return Where(display, line + 1, position - (text.rfind("\n", 0, position) + 1) + 1)


def _char_at(text: str, line: int, column: int) -> str:
    lines = text.splitlines()
    return lines[line][column] if line < len(lines) and column < len(lines[line]) else ""


def read_text(path: str, where=None, key: str = "") -> str:
    """A scene file's text, or a SceneError saying why it cannot be read."""
    try:
        data = read_bytes(path, MAX_SCENE_BYTES)
    except FileNotFoundError:
        raise SceneError(where or path, key, f"file not found: {shown(path)}") from None
    except OSError as e:
        raise SceneError(where or path, key, f"cannot read {shown(path)}: {e.strerror or e}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        good = data[:e.start].decode("utf-8")
        raise SceneError(_where_in(good, path, len(good)), "",
                         f"not UTF-8 text (byte 0x{data[e.start]:02x})") from None


def load(path: str) -> list[MapNode]:
    """The scene file and its includes, included documents first (depth first), each file once."""
    docs: list[MapNode] = []
    _load(path, None, "", (), docs, set())
    return docs


def load_tree(tree: MapNode) -> list[MapNode]:
    """A scene given as a tree (parsed YAML text, or a dict from the Python API) and its includes,
    as load() gives a file's: included documents first, the tree last."""
    docs: list[MapNode] = []
    seen: set = set()
    for k, name, item_where in _includes(tree):
        _load(os.path.normpath(os.path.join(tree.folder, name)), item_where, f"include[{k}]", (), docs, seen)
    docs.append(tree)
    return docs


def _load(path: str, where, key: str, stack: tuple, docs: list, seen: set) -> None:
    real = real_path(path)
    if real in stack:
        chain = " -> ".join(shown(os.path.basename(p)) for p in stack + (real,))
        raise SceneError(where, key, f"include cycle: {chain}")
    if real in seen:
        return                                  # included along another path already
    if len(stack) > MAX_INCLUDE_DEPTH:
        raise SceneError(where, key, f"includes nest more than {MAX_INCLUDE_DEPTH} deep")
    seen.add(real)
    tree = parse(read_text(path, where, key), path, os.path.dirname(path) or ".")
    for k, name, item_where in _includes(tree):
        _load(os.path.normpath(os.path.join(tree.folder, name)), item_where, f"include[{k}]",
              stack + (real,), docs, seen)
    if stack:
        for k in tree:
            if k not in INCLUDABLE:
                raise SceneError(tree.key_where[k], shown(k), "not allowed in an included file "
                                 "(only materials, lights and objects are merged)")
    docs.append(tree)


def _includes(tree: MapNode):
    """(k, file name, where) of each entry of the `include:` list."""
    includes = tree.get("include", [])
    if isinstance(includes, str):
        return [(0, includes, tree.value_where["include"])]
    if not isinstance(includes, list):
        raise SceneError(tree.value_where["include"], "include", "must be a list of file names")
    out = []
    for k, name in enumerate(includes):
        item_where = includes.item_where[k] if isinstance(includes, SeqNode) else tree.value_where["include"]
        if not isinstance(name, str):
            raise SceneError(item_where, f"include[{k}]", "must be a file name")
        out.append((k, name, item_where))
    return out

