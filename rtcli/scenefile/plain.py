"""A scene given as plain Python data (the dict a scene file loads into), located by key path.

The Python API (rtcli/api/) accepts a scene as a dict of dicts, lists, strings,
numbers, booleans and None: what `yaml.safe_load` of a scene file gives. It becomes
the same MapNode/SeqNode tree a file gives (nodes.py), so every check and message
is the one a file gets; a dict has no lines, so its nodes are located at line 0
and a message names `<dict>` and the key path alone:
`<dict>: objects[1].sphere.radius: must be > 0, got -1`.

Tuples count as lists; numpy arrays and numpy numbers, as the lists and numbers they
hold, but for an object's `spheres` and a `mesh` given by `vertices`, kept as arrays (arrays.py); os.PathLike values (pathlib.Path for a texture or a mesh), as strings. Keys
are strings (numbers and booleans become strings, as YAML keys do). Any other value,
a dict or list that contains itself, or nesting deeper than MAX_DEPTH is an error at
its key path. A value that appears twice is converted once, as a YAML alias is.
"""

from __future__ import annotations

import os
from array import array

import numpy as np

from rtcli.errors import SceneError, Where, shown
from rtcli.scenefile.arrays import arrays_of, wants_arrays
from rtcli.scenefile.limits import MAX_DEPTH
from rtcli.scenefile.nodes import MapNode, SeqNode, size_of

DICT = "<dict>"                     # how messages name a scene given as a dict (errors.SOURCES)
_SCALARS = (str, int, float, bool, type(None))


def tree_from_dict(data: dict, folder: str = ".") -> MapNode:
    """The MapNode tree of a scene dict; relative file names in it are relative to `folder`."""
    if not isinstance(data, dict):
        raise SceneError(Where(DICT, 0, 0), "", f"a scene must be a mapping of keys, got {type(data).__name__}")
    return _Converter(folder).value(data, "", 0)


class _Converter:
    """Walks the user's data once; `done` maps id() of each converted dict or list to its node."""

    def __init__(self, folder: str):
        self.folder, self.done, self.path_ids = folder, {}, set()

    def value(self, x, path: str, depth: int):
        x = _plain(x)
        if isinstance(x, _SCALARS):
            return x
        if not isinstance(x, (dict, list, tuple)):
            raise SceneError(Where(DICT, 0, 0), path, "must be a dict, list, string, number, boolean or None, "
                                                      f"got a value of type {shown(type(x).__name__)}")
        if id(x) in self.done:
            return self.done[id(x)]
        if id(x) in self.path_ids:
            raise SceneError(Where(DICT, 0, 0), path, "contains itself (recursive values are not allowed)")
        if depth >= MAX_DEPTH:
            raise SceneError(Where(DICT, 0, 0), path, f"values nest more than {MAX_DEPTH} deep")
        self.path_ids.add(id(x))
        node = self.mapping(x, path, depth) if isinstance(x, dict) else self.sequence(x, path, depth)
        self.path_ids.discard(id(x))
        self.done[id(x)] = node
        return node

    def mapping(self, x: dict, path: str, depth: int) -> MapNode:
        node = MapNode()
        node.file, node.folder, node.duplicates, node._index, node.size = DICT, self.folder, (), None, 1
        for key, item in x.items():
            name = _key(key, path)
            here = f"{path}.{shown(name)}" if path else shown(name)
            if path.endswith("]") and wants_arrays(name, item):         # an object's set of arrays
                node[name] = arrays_of(name, item, here)
                continue
            node[name] = self.value(item, here, depth + 1)
            node.size += size_of(node[name])
        node.places = array("Q", bytes(8 * (1 + 2 * len(node))))
        return node

    def sequence(self, x, path: str, depth: int) -> SeqNode:
        node = SeqNode(self.value(item, f"{path}[{k}]", depth + 1) for k, item in enumerate(x))
        node.file, node.size = DICT, 1 + sum(size_of(v) for v in node)
        node.places = array("Q", bytes(8 * (1 + len(node))))
        return node


def _plain(x):
    """numpy values as Python ones, paths as strings; anything else unchanged."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, os.PathLike):
        return os.fspath(x)
    return x


def _key(key, path: str) -> str:
    key = _plain(key)
    if isinstance(key, str):
        return key
    if isinstance(key, (int, float, bool)):
        return str(key)
    raise SceneError(Where(DICT, 0, 0), path, f"keys must be strings, got a key of type {type(key).__name__}")
