"""A YAML mapping whose entries are not plain: merge keys (`<<`) and keys given twice.

yamlevents.py puts a mapping's entries straight into its node while each key is new
and none is a merge key; from the first that is not, it keeps (key, value) pairs, and
fill_map orders them as PyYAML's flatten_mapping does: the merged entries first, the
first mapping listed winning, then the written ones, which win over merged ones.
Merging copies no value: each entry refers to the merged mapping's own. A key
written twice is recorded (MapNode.duplicates) and reported when the mapping is
read (params.Params; docs/scene-format.md: duplicate keys are errors).
"""

from __future__ import annotations

from array import array

from rtcli.errors import SceneError
from rtcli.scenefile.nodes import MapNode, size_of, unpack

MERGE = object()               # the value of a `<<` key


def fill_map(node: MapNode, pairs: list, places: array, file: str) -> None:
    """Fill `node` from its (key, key_pos, value, value_pos) pairs, in the order of their `<<`
    merge (merged entries first, then the written ones, which win); `places` holds the
    mapping's own position, and gets each key's and value's."""
    merged, written, first, duplicates = [], [], {}, []
    for key, key_pos, value, value_pos in pairs:
        if key is MERGE:
            merged.extend(merge_entries(value, value_pos, file))
            continue
        if key in first:
            duplicates.append((key, unpack(file, key_pos), unpack(file, first[key])))
        first.setdefault(key, key_pos)
        written.append((key, key_pos, value, value_pos))
    slot = {}                                               # key -> its index in places
    for key, key_pos, value, value_pos in merged + written:
        if key in slot:
            k = slot[key]
            node.size -= size_of(node[key])
            places[k], places[k + 1] = key_pos, value_pos
        else:
            slot[key] = len(places)
            places.extend((key_pos, value_pos))
        node[key] = value
        node.size += size_of(value)
    node.places, node.duplicates = places, tuple(duplicates)


def merge_entries(value, value_pos: int, file: str) -> list:
    """(key, key_pos, value, value_pos) of the mappings a `<<` key names, the first listed winning."""
    sources = [value] if isinstance(value, MapNode) else value
    if not isinstance(sources, list) or not all(isinstance(s, MapNode) for s in sources):
        raise SceneError(unpack(file, value_pos), "", "invalid YAML: a merge key (<<) takes a mapping "
                         "or a list of mappings")
    entries = []
    for source in reversed(sources):
        for k, key in enumerate(source):
            entries.append((key, source.places[1 + 2 * k], source[key], source.places[2 + 2 * k]))
    return entries
