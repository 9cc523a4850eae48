"""Safe YAML loading that remembers where every node came from.

Mappings load as `MapNode` (a dict) and sequences as `SeqNode` (a list); each
records its own location and those of its keys and items, so any value can be
reported as `file:line:col`. Anchors, aliases and merge keys (`<<`) work as in
PyYAML's safe loader; Python object tags are refused. `include:` files are
loaded first, relative to the including file's folder, with cycle detection.
"""

from __future__ import annotations

import os
import re

import yaml

from rtcli.errors import SceneError, Where

INCLUDABLE = {"version", "include", "materials", "lights", "objects"}


class MapNode(dict):
    """A YAML mapping with the locations of itself, its keys and its values."""

    where: Where
    key_where: dict
    value_where: dict
    folder: str                             # folder of the file it came from
    duplicates: list                        # (key, where, where_first) of keys given twice; Params reports them


class SeqNode(list):
    """A YAML sequence with the locations of itself and its items."""

    where: Where
    item_where: list


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """The safe loader (libyaml's parser when present) building MapNode/SeqNode; reads 1e-6 as a float."""


_Loader.add_implicit_resolver(        # YAML 1.1 wants a dot in 1.0e-6; people write 1e-6
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def _where(loader: _Loader, mark) -> Where:
    return Where(loader.display, mark.line + 1, mark.column + 1)


def _construct_map(loader: _Loader, node: yaml.MappingNode) -> MapNode:
    first, duplicates = {}, []
    for key_node, _ in node.value:
        if isinstance(key_node, yaml.ScalarNode) and key_node.tag != "tag:yaml.org,2002:merge":
            where = _where(loader, key_node.start_mark)
            if key_node.value in first:
                duplicates.append((key_node.value, where, first[key_node.value]))
            first.setdefault(key_node.value, where)
    loader.flatten_mapping(node)
    result = MapNode()
    result.duplicates = duplicates
    result.where = _where(loader, node.start_mark)
    result.key_where, result.value_where = {}, {}
    result.folder = loader.folder
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        if not isinstance(key, (str, int, float, bool)):
            raise SceneError(_where(loader, key_node.start_mark), "", "keys must be plain names")
        key = str(key)
        result[key] = loader.construct_object(value_node, deep=True)
        result.key_where[key] = _where(loader, key_node.start_mark)
        result.value_where[key] = _where(loader, value_node.start_mark)
    return result


def _construct_seq(loader: _Loader, node: yaml.SequenceNode) -> SeqNode:
    result = SeqNode(loader.construct_object(item, deep=True) for item in node.value)
    result.where = _where(loader, node.start_mark)
    result.item_where = [_where(loader, item.start_mark) for item in node.value]
    return result


_Loader.add_constructor("tag:yaml.org,2002:map", _construct_map)
_Loader.add_constructor("tag:yaml.org,2002:seq", _construct_seq)


def parse(text: str, display: str, folder: str = ".") -> MapNode:
    """Parse one YAML document whose top level must be a mapping."""
    loader = _Loader(text)
    loader.display, loader.folder = display, folder
    try:
        tree = loader.get_single_data()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        where = Where(display, mark.line + 1, mark.column + 1) if mark else display
        problem = e.problem or e.context
        if mark and _char_at(text, mark.line, mark.column) == "\t":
            problem = "tab characters cannot indent YAML (use spaces)"
        raise SceneError(where, "", f"invalid YAML: {problem}") from None
    except yaml.YAMLError as e:
        raise SceneError(display, "", f"invalid YAML: {e}") from None
    except RecursionError:
        raise SceneError(display, "", "invalid YAML: structure nested too deeply") from None
    finally:
        loader.dispose()
    if tree is None:
        tree = MapNode()
        tree.where, tree.key_where, tree.value_where = Where(display, 1, 1), {}, {}
        tree.folder, tree.duplicates = folder, []
    if not isinstance(tree, MapNode):
        raise SceneError(Where(display, 1, 1), "", "a scene must be a mapping of keys")
    return tree


def _char_at(text: str, line: int, column: int) -> str:
    lines = text.splitlines()
    return lines[line][column] if line < len(lines) and column < len(lines[line]) else ""


def read_text(path: str, where=None, key: str = "") -> str:
    """A file's text, or a SceneError saying why it cannot be read."""
    try:
        with open(path, encoding="utf-8") as f:
            return f.read()
    except FileNotFoundError:
        raise SceneError(where or path, key, f"file not found: {path}") from None
    except IsADirectoryError:
        raise SceneError(where or path, key, f"is a folder, not a file: {path}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise SceneError(where or path, key, f"cannot read {path}: {e}") from None


def load(path: str) -> list[MapNode]:
    """The scene file and its includes, included documents first (depth first)."""
    docs: list[MapNode] = []
    _load(path, None, "", (), docs)
    return docs


def _load(path: str, where, key: str, stack: tuple, docs: list) -> None:
    real = os.path.realpath(path)
    if real in stack:
        chain = " -> ".join(os.path.basename(p) for p in stack + (real,))
        raise SceneError(where, key, f"include cycle: {chain}")
    tree = parse(read_text(path, where, key), path, os.path.dirname(path) or ".")
    includes = tree.get("include", [])
    if isinstance(includes, str):
        includes = [includes]
    if not isinstance(includes, list):
        raise SceneError(tree.value_where["include"], "include", "must be a list of file names")
    for k, name in enumerate(includes):
        item_where = includes.item_where[k] if isinstance(includes, SeqNode) else tree.value_where["include"]
        if not isinstance(name, str):
            raise SceneError(item_where, f"include[{k}]", "must be a file name")
        _load(os.path.normpath(os.path.join(tree.folder, name)), item_where, f"include[{k}]",
              stack + (real,), docs)
    if stack:
        for k in tree:
            if k not in INCLUDABLE:
                raise SceneError(tree.key_where[k], k, "not allowed in an included file "
                                 "(only materials, lights and objects are merged)")
    docs.append(tree)
