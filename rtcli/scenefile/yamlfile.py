"""Safe YAML loading that remembers where every value came from.

Mappings load as `MapNode` (a dict) and sequences as `SeqNode` (a list); each
records its own location and those of its keys and items, so any value can be
reported as `file:line:col`. Anchors, aliases and merge keys (`<<`) work as in
PyYAML's safe loader; Python object tags are refused. `include:` files are
loaded first, relative to the including file's folder, each file once, with
cycle detection.

The tree is built straight from the parser's events, without PyYAML's node
graph, and locations are kept packed in one array per mapping or list: a big
scene costs little more than its values. Loading is bounded
(docs/scene-format.md, "Limits"): values nest at most MAX_DEPTH deep, aliases
(each counted as a copy of what it names) add at most ALIAS_BUDGET values, an
alias may not name a collection that contains it, and files are size-limited
regular files (limits.py, files.py).
"""

from __future__ import annotations

import os
import re
import sys
from array import array

import yaml

from rtcli.errors import SceneError, Where, quoted, shown
from rtcli.scenefile.files import read_bytes
from rtcli.scenefile.limits import ALIAS_BUDGET, MAX_DEPTH, MAX_INCLUDE_DEPTH, MAX_SCENE_BYTES, RANGE

INCLUDABLE = {"version", "include", "materials", "lights", "objects"}

_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_TAG + t for t in ("null", "bool", "int", "float", "str", "binary", "timestamp")}
_PLAIN_FLOAT = re.compile(r"-?[0-9]+\.[0-9]*\Z")      # read as a float by every YAML 1.1 rule too
_PLAIN_INT = re.compile(r"-?[1-9][0-9]{0,17}\Z|0\Z")
_MERGE = object()               # the value of a `<<` key


def _pack(mark) -> int:
    return (mark.line + 1) << 32 | (mark.column + 1)


class MapNode(dict):
    """A YAML mapping with the locations of itself, its keys and its values.

    `places` holds packed (line, column) pairs: the mapping's own, then key and
    value of each entry in the dict's order.
    """

    __slots__ = ("file", "folder", "places", "duplicates", "size", "_index")

    @classmethod
    def empty(cls, where: Where, folder: str) -> MapNode:
        """An empty mapping located at `where` (a shape written as `sphere:` with no value)."""
        node = cls()
        node.file, node.folder, node.duplicates, node.size, node._index = where.file, folder, (), 1, None
        node.places = array("Q", [where.line << 32 | where.column])
        return node

    def _at(self, k: int) -> Where:
        p = self.places[k]
        return Where(self.file, p >> 32, p & 0xFFFFFFFF)

    @property
    def where(self) -> Where:
        return self._at(0)

    @property
    def key_where(self) -> _Places:
        return _Places(self, 1)

    @property
    def value_where(self) -> _Places:
        return _Places(self, 2)

    def index(self, key) -> int:
        """The position of `key` in the dict's order (KeyError if absent)."""
        if len(self) <= 8:
            for k, name in enumerate(self):
                if name == key:
                    return k
            raise KeyError(key)
        if self._index is None:
            self._index = {name: k for k, name in enumerate(self)}
        return self._index[key]


class _Places:
    """key -> Where of a MapNode's keys (slot 1) or values (slot 2); read only."""

    __slots__ = ("node", "slot")

    def __init__(self, node: MapNode, slot: int):
        self.node, self.slot = node, slot

    def __getitem__(self, key) -> Where:
        return self.node._at(2 * self.node.index(key) + self.slot)

    def get(self, key, default=None):
        return self[key] if key in self.node else default

    def __contains__(self, key) -> bool:
        return key in self.node


class SeqNode(list):
    """A YAML sequence with the locations of itself and its items (`places`: its own, then each item's)."""

    __slots__ = ("file", "places", "size")

    def _at(self, k: int) -> Where:
        p = self.places[k]
        return Where(self.file, p >> 32, p & 0xFFFFFFFF)

    @property
    def where(self) -> Where:
        return self._at(0)

    @property
    def item_where(self) -> _Items:
        return _Items(self)


class _Items:
    """index -> Where of a SeqNode's items."""

    __slots__ = ("seq",)

    def __init__(self, seq: SeqNode):
        self.seq = seq

    def __getitem__(self, k: int) -> Where:
        return self.seq._at(k + 1)

    def __len__(self) -> int:
        return len(self.seq)


def _size(value) -> int:
    """How many values `value` stands for, counting what aliases repeat."""
    return value.size if isinstance(value, (MapNode, SeqNode)) else 1


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """The safe loader's parser and scalar rules (libyaml's parser when present); reads 1e-6 as a float."""


_Loader.add_implicit_resolver(        # YAML 1.1 wants a dot in 1.0e-6; people write 1e-6
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


class _Frame:
    """A mapping or list being read: the node and, for a mapping, its (key, value) events so far."""

    __slots__ = ("node", "anchor", "pairs", "key", "key_pos", "places", "size")

    def __init__(self, node, anchor, pos):
        self.node, self.anchor, self.places, self.size = node, anchor, array("Q", [pos]), 1
        self.pairs, self.key, self.key_pos = [], None, 0


class _Builder:
    """Builds one document's MapNode/SeqNode tree from parser events, with the limits above."""

    def __init__(self, loader: _Loader, display: str, folder: str):
        self.loader, self.file, self.folder = loader, display, folder
        self.anchors: dict = {}            # name -> (value, where) of finished anchored values
        self.open: set = set()             # anchors of collections still being read
        self.budget = ALIAS_BUDGET

    def where(self, mark) -> Where:
        return Where(self.file, mark.line + 1, mark.column + 1)

    def document(self):
        """The single document's value; None for an empty stream."""
        get, check = self.loader.get_event, self.loader.check_event
        get()                                                   # stream start
        if check(yaml.StreamEndEvent):
            return None
        get()                                                   # document start
        value = self.value()
        get()                                                   # document end
        if not check(yaml.StreamEndEvent):
            raise SceneError(self.where(get().start_mark), "", "invalid YAML: a scene is a single document "
                             "(found a second one)")
        return value

    def value(self):
        """The next complete value, read without recursion."""
        stack: list[_Frame] = []
        while True:
            event = self.loader.get_event()
            kind = type(event)
            if kind is yaml.MappingStartEvent or kind is yaml.SequenceStartEvent:
                stack.append(self.start(event, len(stack)))
                continue
            if kind is yaml.ScalarEvent:
                value, pos = self.scalar(event), _pack(event.start_mark)
            elif kind is yaml.AliasEvent:
                value, pos = self.alias(event), _pack(event.start_mark)
            else:                                               # mapping or sequence end
                value = self.finish(stack.pop())
                pos = value.places[0]
            if not stack:
                return value
            self.add(stack[-1], value, pos)

    def start(self, event, depth: int) -> _Frame:
        if depth >= MAX_DEPTH:
            raise SceneError(self.where(event.start_mark), "", f"values nest more than {MAX_DEPTH} deep")
        if event.tag not in (None, "!", _TAG + "map", _TAG + "seq"):
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: unsupported tag {quoted(event.tag)}")
        if event.anchor is not None:
            self.check_anchor(event)
            self.open.add(event.anchor)
        node = MapNode() if type(event) is yaml.MappingStartEvent else SeqNode()
        return _Frame(node, event.anchor, _pack(event.start_mark))

    def check_anchor(self, event) -> None:
        if event.anchor in self.anchors or event.anchor in self.open:
            first = self.anchors.get(event.anchor, (None, None))[1]
            at = f" (first given at line {first.line})" if first else ""
            raise SceneError(self.where(event.start_mark), "", f"duplicate anchor &{shown(event.anchor)}{at}")

    def scalar(self, event):
        tag, text = event.tag, event.value
        if tag is None or tag == "!":
            if event.implicit[0] and _PLAIN_FLOAT.match(text):
                value = float(text)
                return self.anchored(event, value)
            if event.implicit[0] and _PLAIN_INT.match(text):
                return self.anchored(event, int(text))
            tag = self.loader.resolve(yaml.ScalarNode, text, event.implicit)
        if tag == _TAG + "str":
            value = sys.intern(text) if len(text) <= 64 else text
        elif tag == _TAG + "merge":
            value = _MERGE
        elif tag in _SCALAR_TAGS:
            value = self.construct(tag, event)
        else:
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: unsupported tag {quoted(tag)}")
        return self.anchored(event, value)

    def construct(self, tag: str, event):
        node = yaml.ScalarNode(tag, event.value, event.start_mark, event.end_mark, event.style)
        try:
            return self.loader.yaml_constructors[tag](self.loader, node)
        except (ValueError, KeyError, TypeError, AttributeError):
            digits = sum(c.isdigit() for c in event.value)
            if digits > 300:            # past a float, or past Python's 4300-digit limit on int()
                raise SceneError(self.where(event.start_mark), "", f"a number of {digits} digits is out of "
                                 f"range (numbers must be {RANGE})") from None
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: {quoted(event.value)} "
                             f"is not a valid !!{tag.rsplit(':', 1)[-1]}") from None

    def anchored(self, event, value):
        if event.anchor is not None:
            self.check_anchor(event)
            self.anchors[event.anchor] = (value, self.where(event.start_mark))
        return value

    def alias(self, event):
        name = event.anchor
        if name in self.open:
            raise SceneError(self.where(event.start_mark), "", f"alias *{shown(name)} names a collection "
                             "that contains it (recursive values are not allowed)")
        if name not in self.anchors:
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: undefined alias *{shown(name)}")
        value = self.anchors[name][0]
        self.budget -= _size(value)
        if self.budget < 0:
            raise SceneError(self.where(event.start_mark), "", f"aliases repeat more than {ALIAS_BUDGET:,} values "
                             "(each alias counts as a copy of what it names)")
        return value

    def add(self, frame: _Frame, value, pos: int) -> None:
        """Deliver a finished value, which starts at packed position `pos`, to the collection being read."""
        node = frame.node
        if type(node) is SeqNode:
            node.append(value)
            frame.places.append(pos)
            frame.size += _size(value)
        elif frame.key is None:
            frame.key, frame.key_pos = self.key(value, pos), pos
        else:
            frame.pairs.append((frame.key, frame.key_pos, value, pos))
            frame.key = None

    def key(self, value, pos: int):
        if value is _MERGE:
            return value
        if not isinstance(value, (str, int, float, bool)):
            raise SceneError(_unpack(self.file, pos), "", "keys must be plain names")
        return value if type(value) is str else sys.intern(str(value))

    def finish(self, frame: _Frame):
        node = frame.node
        node.file, node.size = self.file, frame.size
        if type(node) is MapNode:
            node.folder, node._index = self.folder, None
            self.fill_map(node, frame)
        else:
            node.places = frame.places
        if frame.anchor is not None:
            self.open.discard(frame.anchor)
            self.anchors[frame.anchor] = (node, node.where)
        return node

    def fill_map(self, node: MapNode, frame: _Frame) -> None:
        """Merged entries first (as PyYAML's flatten_mapping orders them), then the written ones, which win."""
        places, merged, written, first, duplicates = frame.places, [], [], {}, []
        for key, key_pos, value, value_pos in frame.pairs:
            if key is _MERGE:
                merged.extend(self.merge_entries(value, value_pos))
                continue
            if key in first:
                duplicates.append((key, _unpack(self.file, key_pos), _unpack(self.file, first[key])))
            first.setdefault(key, key_pos)
            written.append((key, key_pos, value, value_pos))
        slot = {}                                               # key -> its index in places
        for key, key_pos, value, value_pos in merged + written:
            if key in slot:
                k = slot[key]
                node.size -= _size(node[key])
                places[k], places[k + 1] = key_pos, value_pos
            else:
                slot[key] = len(places)
                places.extend((key_pos, value_pos))
            node[key] = value
            node.size += _size(value)
        node.places, node.duplicates = places, tuple(duplicates)

    def merge_entries(self, value, value_pos) -> list:
        """(key, key_pos, value, value_pos) of the mappings a `<<` key names, the first listed winning."""
        sources = [value] if isinstance(value, MapNode) else value
        if not isinstance(sources, list) or not all(isinstance(s, MapNode) for s in sources):
            raise SceneError(_unpack(self.file, value_pos), "", "invalid YAML: a merge key (<<) takes a mapping "
                             "or a list of mappings")
        entries = []
        for source in reversed(sources):
            for k, key in enumerate(source):
                entries.append((key, source.places[1 + 2 * k], source[key], source.places[2 + 2 * k]))
        return entries


def _unpack(file: str, p: int) -> Where:
    return Where(file, p >> 32, p & 0xFFFFFFFF)


def parse(text: str, display: str, folder: str = ".") -> MapNode:
    """Parse one YAML document whose top level must be a mapping."""
    loader = _Loader(text)
    try:
        tree = _Builder(loader, display, folder).document()
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
    return SceneError(where, "", f"invalid YAML: {problem}")


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


def _load(path: str, where, key: str, stack: tuple, docs: list, seen: set) -> None:
    real = os.path.realpath(path)
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

