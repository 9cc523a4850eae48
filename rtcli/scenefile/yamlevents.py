"""YAML parser events -> a tree of MapNode/SeqNode, with the loading limits.

The safe loader's parser (libyaml's when present) and its scalar rules, but
no node graph: each value is built as its events arrive, without recursion.
Mappings and lists nest at most MAX_DEPTH deep; aliases, each counted as a copy
of what it names, repeat at most ALIAS_BUDGET values; an alias may not name a
collection that contains it; merge keys (`<<`) merge as PyYAML's flatten_mapping
does, without copying (yamlmerge.py; docs/scene-format.md, "Limits").
"""

from __future__ import annotations

import re
import sys
from array import array

import yaml

from rtcli.errors import SceneError, Where, quoted, shown
from rtcli.scenefile.limits import ALIAS_BUDGET, MAX_DEPTH, RANGE
from rtcli.scenefile.nodes import CommentedColor, MapNode, SeqNode, pack, size_of, unpack
from rtcli.scenefile.yamlmerge import MERGE, fill_map

_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_TAG + t for t in ("null", "bool", "int", "float", "str", "binary", "timestamp")}
_PLAIN_FLOAT = re.compile(r"-?[0-9]+\.[0-9]*\Z")      # read as a float by every YAML 1.1 rule too
_PLAIN_INT = re.compile(r"-?[1-9][0-9]{0,17}\Z|0\Z")
_HEX_COMMENT = re.compile(r"[ \t]*(#[0-9a-fA-F]{6})\b")     # an unquoted color, read as a comment


class Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """The safe loader's parser and scalar rules (libyaml's parser when present); reads 1e-6 as a float."""


Loader.add_implicit_resolver(        # YAML 1.1 wants a dot in 1.0e-6; people write 1e-6
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


# First characters of plain scalars that an implicit resolver may read as something other than
# a string (a number, a bool, null, a merge key, ...); any other plain scalar is a string.
_RESOLVED = frozenset(Loader.yaml_implicit_resolvers) if None not in Loader.yaml_implicit_resolvers else None


class _Frame:
    """A mapping or list being read. A mapping's entries go straight into its node while
    they are plain (no merge key, no key twice); from the first that is not, the
    (key, value) pairs are kept instead, and yamlmerge.fill_map orders them when it ends."""

    __slots__ = ("node", "anchor", "pairs", "key", "key_pos", "places", "size")

    def __init__(self, node, anchor, pos):
        self.node, self.anchor, self.places, self.size = node, anchor, array("Q", [pos]), 1
        self.pairs, self.key, self.key_pos = None, None, 0

class Builder:
    """Builds one document's MapNode/SeqNode tree from parser events, with the limits above."""

    def __init__(self, loader: Loader, display: str, folder: str, text: str = ""):
        self.loader, self.file, self.folder = loader, display, folder
        self.text, self.comments = text, "#" in text     # the source, for commented_color
        self.starts: array | None = None                # where its lines start, found when first needed
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
        """The next complete value, read without recursion.

        The common events are handled here, inline (a big scene is tens of thousands of
        them): a plain or quoted scalar without tag or anchor, and the entries of lists and
        mappings; the rest go through scalar(), alias(), add() and finish()."""
        stack: list[_Frame] = []
        get, intern, resolved = self.loader.get_event, sys.intern, _RESOLVED
        plain_float, plain_int = _PLAIN_FLOAT.match, _PLAIN_INT.match
        while True:
            event = get()
            kind = type(event)
            if kind is yaml.ScalarEvent:
                mark = event.start_mark
                pos = (mark.line + 1) << 32 | (mark.column + 1)
                if event.tag is not None or event.anchor is not None:
                    value = self.scalar(event)
                else:
                    text = event.value
                    if event.implicit[0]:                       # plain
                        if resolved is not None and text and text[0] not in resolved:
                            value = intern(text) if len(text) <= 64 else text
                        elif plain_float(text):
                            value = float(text)
                        elif plain_int(text):
                            value = int(text)
                        else:
                            value = self.scalar(event)
                    elif event.implicit[1]:                     # quoted: a string
                        value = intern(text) if len(text) <= 64 else text
                    else:
                        value = self.scalar(event)
            elif kind is yaml.MappingStartEvent or kind is yaml.SequenceStartEvent:
                stack.append(self.start(event, len(stack)))
                continue
            elif kind is yaml.AliasEvent:
                value, pos = self.alias(event), pack(event.start_mark)
            else:                                               # mapping or sequence end
                value = self.finish(stack.pop())
                pos = value.places[0]
            if not stack:
                return value
            frame = stack[-1]
            node = frame.node
            if type(node) is SeqNode:
                node.append(value)
                frame.places.append(pos)
                frame.size += value.size if type(value) is MapNode or type(value) is SeqNode else 1
            elif frame.key is None:
                frame.key, frame.key_pos = (value if type(value) is str else self.key(value, pos)), pos
            elif frame.pairs is None and frame.key is not MERGE and frame.key not in node:
                node[frame.key] = value
                places = frame.places
                places.append(frame.key_pos)
                places.append(pos)
                frame.size += value.size if type(value) is MapNode or type(value) is SeqNode else 1
                frame.key = None
            else:
                self.add(frame, value, pos)

    def start(self, event, depth: int) -> _Frame:
        """The frame of a mapping or list that starts at `event`, inside `depth` others."""
        if depth >= MAX_DEPTH:
            raise SceneError(self.where(event.start_mark), "", f"values nest more than {MAX_DEPTH} deep")
        if event.tag not in (None, "!", _TAG + "map", _TAG + "seq"):
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: unsupported tag {quoted(event.tag)}")
        if event.anchor is not None:
            self.check_anchor(event)
            self.open.add(event.anchor)
        node = MapNode() if type(event) is yaml.MappingStartEvent else SeqNode()
        return _Frame(node, event.anchor, pack(event.start_mark))

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
            value = MERGE
        elif tag == _TAG + "null" and not text and event.implicit[0]:
            value = self.commented_color(event.start_mark)
        elif tag in _SCALAR_TAGS:
            value = self.construct(tag, event)
        else:
            raise SceneError(self.where(event.start_mark), "", f"invalid YAML: unsupported tag {quoted(tag)}")
        return self.anchored(event, value)

    def commented_color(self, mark):
        """None for an empty value, or a CommentedColor when an unquoted #rrggbb follows it on its
        line (`diffuse: #ff8000`, which YAML reads as an empty value and a comment)."""
        if not self.comments:
            return None
        if self.starts is None:
            self.starts = array("Q", [0])
            self.starts.extend(m.end() for m in re.finditer("\n", self.text))
        if mark.line >= len(self.starts):
            return None
        start = self.starts[mark.line]
        end = self.text.find("\n", start)
        found = _HEX_COMMENT.match(self.text, start + mark.column, len(self.text) if end < 0 else end)
        return CommentedColor(found.group(1)) if found else None

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
        self.budget -= size_of(value)
        if self.budget < 0:
            raise SceneError(self.where(event.start_mark), "", f"aliases repeat more than {ALIAS_BUDGET:,} values "
                             "(each alias counts as a copy of what it names)")
        return value

    def add(self, frame: _Frame, value, pos: int) -> None:
        """Deliver a finished value, which starts at packed position `pos`, to the collection being read
        (value() does the common cases itself)."""
        node = frame.node
        if type(node) is SeqNode:
            node.append(value)
            frame.places.append(pos)
            frame.size += size_of(value)
        elif frame.key is None:
            frame.key, frame.key_pos = self.key(value, pos), pos
        else:
            if frame.pairs is None:                 # the entries so far, as pairs: fill_map orders them
                places = frame.places
                frame.pairs = [(key, places[1 + 2 * k], node[key], places[2 + 2 * k]) for k, key in enumerate(node)]
                node.clear()
                frame.places, frame.size = array("Q", places[:1]), 1
            frame.pairs.append((frame.key, frame.key_pos, value, pos))
            frame.key = None

    def key(self, value, pos: int):
        if value is MERGE:
            return value
        if not isinstance(value, (str, int, float, bool)):
            raise SceneError(unpack(self.file, pos), "", "keys must be plain names")
        if type(value) is bool:
            return "true" if value else "false"                  # as YAML writes them, not Python
        return value if type(value) is str else sys.intern(str(value))

    def finish(self, frame: _Frame):
        node = frame.node
        node.file, node.size = self.file, frame.size
        if type(node) is MapNode:
            node.folder, node._index = self.folder, None
            if frame.pairs is None:
                node.places, node.duplicates = frame.places, ()
            else:
                fill_map(node, frame.pairs, frame.places, self.file)
        else:
            node.places = frame.places
        if frame.anchor is not None:
            self.open.discard(frame.anchor)
            self.anchors[frame.anchor] = (node, node.where)
        return node
