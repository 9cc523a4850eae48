"""The node budget of `rtcli explain` (docs/debugging.md, A bounded tree): a glass scene with a
large max_depth has a ray tree of up to 2^max_depth rays, far more than anyone reads. The tree
shows its rays level by level up to the deepest depth whose rays, with all those above, fit in
the budget; each ray at the next depth is shown as a summary: how many rays its subtree has and
what it adds to its parent (its weight times its color, the engine's own numbers).

`levels` counts the rays of each depth with a recorder that keeps nothing else (a first pass of
the numpy engine over the pixel's ray); `Summary` is the recorder of a summarised subtree.
"""

from __future__ import annotations

import numpy as np

from rtcli.wavefront.trace import Log

MAX_NODES = 1000                   # the default budget: rays shown per sample's tree


class Levels(Log):
    """Counts the rays traced at each depth (1: the primary)."""

    def __init__(self):
        self.count: dict[int, int] = {}

    def rays(self, rays, depth: int, hits) -> None:
        self.count[depth] = self.count.get(depth, 0) + len(rays)


def deepest_shown(count: dict[int, int], max_nodes: int) -> int | None:
    """The deepest depth whose rays and all above fit in max_nodes (at least 1: the primary is
    always shown), or None when the whole tree fits."""
    if sum(count.values()) <= max_nodes:
        return None
    total, depth = 0, 1
    for d in sorted(count):
        total += count[d]
        if total > max_nodes:
            break
        depth = d
    return depth


class Summary(Log):
    """The recorder of a summarised subtree: counts its rays into `node.more` and keeps the color
    the engine returned for its first ray (node.value); the rays below it share its count."""

    def __init__(self, node, top: bool = True):
        self.node, self.top = node, top

    def rays(self, rays, depth: int, hits) -> None:
        self.node.more += len(rays)
        if self.top:
            self.node.origin, self.node.direction = rays.o[:, 0].copy(), rays.d[:, 0].copy()

    def child(self, rows, kind: str, weights) -> Summary:
        return Summary(self.node, top=False)

    def color(self, color) -> None:
        if self.top:
            self.node.value = np.asarray(color[:, 0], float).copy()
