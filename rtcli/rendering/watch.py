"""`rtcli render --watch`: render a scene again whenever it or a file it reads changes (README.md, `--watch`).

The files are the scene, its includes, meshes and textures, and a file a failed load
looked for and did not find (creating it is a change too). Loading stamps each one
with its size, modification time and inode as it reads it (scenefile/files.py); the
watch then polls those stamps a few times a second, so a save made while a render runs
is seen when it ends. A change is rendered once the files have held still for one poll,
so a save caught half-written is not read.

Every render runs in this process, so the compiled engine's machine code, loaded for
the first render, serves the next ones at once, and a mesh whose file did not change
is reused as built, without reading its file or building its BVH again
(scenefile/reuse.py). A scene that fails to load or render prints its one-line error
and the watch goes on; Ctrl-C ends it (cli.py).
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable

from rtcli.errors import RtcliError, one_line
from rtcli.scenefile.files import recording_stamps, stamp
from rtcli.scenefile.reuse import Kept, reusing

POLL = 0.25                        # seconds between looks at the files


def watch(scene: str, render: Callable[[], None], error: Callable[[str], None], poll: float = POLL) -> None:
    """Call render() (which loads `scene`, renders and writes it) now and after every change of
    the files it read; a failure goes to error() as its one line. Runs until interrupted."""
    kept = Kept()
    while True:
        with recording(scene, kept) as seen:
            try:
                render()
            except (RtcliError, MemoryError) as e:
                error(f"error: {one_line(str(e) or 'out of memory')}")
        _wait_for_change(seen, poll)


@contextlib.contextmanager
def recording(scene: str, kept: Kept):
    """The stamps of the files a load within the block reads (the scene's own even when it was
    never read), the meshes of the previous load in `kept` reused when their files did not change."""
    path = os.path.realpath(scene)
    with recording_stamps() as seen, reusing(kept):
        try:
            yield seen
        finally:
            seen.setdefault(path, _now(path))


def _now(path: str):
    try:
        return stamp(os.stat(path))
    except OSError:
        return None


class Changes:
    """Whether the files whose stamps a load recorded (`seen`) changed: poll() looks once, and is
    true when a stamp differs from `seen`'s and held still since the previous look, so a save
    caught half-written is not taken. The watch polls it between sleeps; `rtcli preview` between
    the tiles of a render, which the change then stops (rtcli/preview/)."""

    def __init__(self, seen: dict):
        self.seen, self.last = seen, seen

    def poll(self) -> bool:
        now = {path: _now(path) for path in self.seen}
        settled = now != self.seen and now == self.last
        self.last = now
        return settled


def _wait_for_change(seen: dict, poll: float) -> None:
    """Return when a file's stamp differs from `seen`'s and has then held still for one poll."""
    changes = Changes(seen)
    while True:
        time.sleep(poll)
        if changes.poll():
            return
