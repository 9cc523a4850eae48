"""Parts of a scene built once and shared by the frames of an animation (docs/scene-format.md, Animation).

Keyframes change only the camera, lights, transforms and material coefficients,
never a shape or a texture. Each frame is built from a copy of the scene's tree in
which only the mappings and lists on the way to a keyframed value are new; a shape or
texture whose mapping is the same object in every frame's tree is built in the first
frame and reused (a mesh is read and its BVH built once, not once a frame).
"""

from __future__ import annotations

import contextlib
import contextvars

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
