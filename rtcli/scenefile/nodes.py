"""The tree a scene file loads into: mappings and lists that know where they came from.

`MapNode` (a dict) and `SeqNode` (a list) keep their locations packed, a
(line << 32 | column) integer each, in one array per node: the node's own, then
each key's and value's (or each item's). Where objects are made only when asked
for, so a scene of a million objects costs little more than its values.
`size` counts the values a node stands for, what aliases repeat included.
"""

from __future__ import annotations

from array import array

from rtcli.errors import Where


def pack(mark) -> int:
    """A parser mark (0-based line and column) as one packed 1-based position."""
    return (mark.line + 1) << 32 | (mark.column + 1)


def unpack(file: str, p: int) -> Where:
    return Where(file, p >> 32, p & 0xFFFFFFFF)


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
        return unpack(self.file, self.places[k])

    @property
    def where(self) -> Where:
        return self._at(0)

    @property
    def key_where(self) -> _Places:
        return _Places(self, 1)

    @property
    def value_where(self) -> _Places:
        return _Places(self, 2)

    def copy(self) -> MapNode:
        """A shallow copy with its own locations, for a copy whose values change (animation.py)."""
        node = MapNode(self)
        node.file, node.folder, node.duplicates, node.size = self.file, self.folder, self.duplicates, self.size
        node.places, node._index = array("Q", self.places), None
        return node

    def put(self, key, value, place: int | None = None) -> None:
        """Replace an existing key's value, and where the value is said to be (a packed place)."""
        self[key] = value
        if place is not None:
            self.places[2 * self.index(key) + 2] = place

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
        return unpack(self.file, self.places[k])

    @property
    def where(self) -> Where:
        return self._at(0)

    @property
    def item_where(self) -> _Items:
        return _Items(self)

    def copy(self) -> SeqNode:
        """A shallow copy with its own locations (see MapNode.copy)."""
        seq = SeqNode(self)
        seq.file, seq.size, seq.places = self.file, self.size, array("Q", self.places)
        return seq

    def put(self, k: int, value, place: int | None = None) -> None:
        """Replace item k, and where it is said to be (a packed place)."""
        self[k] = value
        if place is not None:
            self.places[k + 1] = place


class _Items:
    """index -> Where of a SeqNode's items."""

    __slots__ = ("seq",)

    def __init__(self, seq: SeqNode):
        self.seq = seq

    def __getitem__(self, k: int) -> Where:
        return self.seq._at(k + 1)

    def __len__(self) -> int:
        return len(self.seq)


class CommentedColor:
    """The empty value YAML makes of `diffuse: #ff8000`: an unquoted # starts a comment.
    It stands in the tree where None would, so that an error about it can say why."""

    __slots__ = ("text",)

    def __init__(self, text: str):
        self.text = text                  # the #rrggbb the comment begins with

    def __repr__(self) -> str:
        return f"CommentedColor({self.text!r})"


def size_of(value) -> int:
    """How many values `value` stands for, counting what aliases repeat."""
    return value.size if isinstance(value, (MapNode, SeqNode)) else 1
