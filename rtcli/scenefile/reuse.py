"""Parts of a scene built once and used again: by an animation's frames, and by a watch's loads.

Within one load (docs/scene-format.md, Animation). Keyframes change only the camera,
lights, transforms and material coefficients, never a shape or a texture. Each frame
is built from a copy of the scene's tree in which only the mappings and lists on the
way to a keyframed value are new; a shape or texture whose mapping is the same object
in every frame's tree is built in the first frame and reused (`sharing`, `reused`): a
mesh is read and its BVH built once, not once a frame.

From one load to the next (`rtcli render --watch`, README.md, Commands). Reading an
OBJ file and building its triangles' BVH is nearly all the time a mesh scene takes to
load (scenes/bunny.yaml: about 1.8 s, and 0.01 s with its mesh kept). A watch loads the
scene again after every edit, and usually the mesh file did not change: within
`reusing(kept)` the OBJ data of a file whose stat (device, inode, size, modification
time) is the one it had at the previous load is reused, and so is the mesh built from
it with the same parameters (`file_data`, `shape`). The file is still checked (a
regular file within its size limit) and recorded as an input, as when it is read.
What a load did not use is dropped at its end, so a watch holds one load's meshes (two
across a load that failed). Outside `reusing`, every load reads and builds afresh.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
from collections.abc import Callable

import numpy as np

from rtcli.scenefile.files import check_input

# --- within one load: an animation's frames ---
_parts: contextvars.ContextVar[Parts | None] = contextvars.ContextVar("rtcli_reused_parts", default=None)


class Parts:
    """Built parts by the identity of the mapping they were built from (and what else they depend on).

    `copies` holds the ids of the mappings copied for the frame being built: they are
    new in every frame, so what is built from them is never kept.
    """

    def __init__(self):
        self.built: dict = {}
        self.copies: set[int] = set()

    def get(self, node, extra, make):
        key = (id(node), extra)
        hit = self.built.get(key)
        if hit is not None and hit[0] is node:        # the node is kept alive, so its id stays its own
            return hit[1]
        value = make()
        if id(node) not in self.copies:
            self.built[key] = (node, value)
        return value


def reused(node, extra, make):
    """make(), or what it gave for the same `node` and `extra` in an earlier frame."""
    parts = _parts.get()
    return make() if parts is None else parts.get(node, extra, make)


@contextlib.contextmanager
def sharing(parts: Parts):
    """Builds inside the block reuse `parts`."""
    token = _parts.set(parts)
    try:
        yield parts
    finally:
        _parts.reset(token)


# --- from one load to the next: a watch ---
class Kept:
    """What the last load made, by key, and what the current one has used so far."""

    def __init__(self):
        self.previous: dict = {}
        self.used: dict = {}

    def get(self, key, make: Callable):
        """The value kept under `key` from the previous load (or this one), else make()'s."""
        value = self.used.get(key)
        if value is None:
            value = self.previous.get(key)
        if value is None:
            value = make()
        self.used[key] = value
        return value

    def next_load(self, failed: bool = False) -> None:
        """Keep what the load that just ended used and drop the rest; after a failed load (a
        broken edit, which may have stopped before some meshes) keep both."""
        self.previous, self.used = ({**self.previous, **self.used} if failed else self.used), {}


_kept: contextvars.ContextVar[Kept | None] = contextvars.ContextVar("rtcli_kept", default=None)


@contextlib.contextmanager
def reusing(kept: Kept):
    """Loads inside the block take unchanged meshes from `kept` and leave theirs in it."""
    token, failed = _kept.set(kept), True
    try:
        yield kept
        failed = False
    finally:
        _kept.reset(token)
        kept.next_load(failed)


def file_data(path: str, limit: int, read: Callable):
    """read()'s data of the file at `path`, or the data read from it at the previous load when its
    stat is unchanged. The file is checked as read() would (check_input) either way."""
    kept = _kept.get()
    if kept is None:
        return read()
    check_input(path, limit)
    st = os.stat(path)
    return kept.get(("file", os.path.realpath(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns), read)


def shape(cls, values: dict, files: dict, make: Callable):
    """make()'s shape of class `cls`, or the one made at the previous load from the same `values`,
    where the values of file parameters (keys of `files`) are compared as the same objects
    (file_data returns the same object for an unchanged file; that object is kept as long
    as the shape is, so its id cannot pass to other data meanwhile)."""
    kept = _kept.get()
    if kept is None or not files:
        return make()
    key = ("shape", cls) + tuple((k, id(v) if k in files else _comparable(v)) for k, v in sorted(values.items()))
    return kept.get(key, make)


def _comparable(value):
    if isinstance(value, np.ndarray):
        return value.dtype.str, value.shape, value.tobytes()
    return type(value).__name__, value
