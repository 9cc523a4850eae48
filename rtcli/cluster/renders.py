"""A still or an animation rendered on a cluster (README.md, Clusters): the cluster of one
command reached once (Reach), a still's tiles and an animation's frames sent as tasks
(session.py) and their results taken as they finish, placed as a local render places them."""

from __future__ import annotations

import contextlib

from rtcli.cluster.bundle import Bundle
from rtcli.cluster.session import Session
from rtcli.rendering.tiles import assemble, plan
from rtcli.stats import Stats


class Reach:
    """The cluster of one command (a target.Target), connected when a render first needs it and
    closed at the end of the `with` block: the scenes of a run share one connection (and one
    --local-cluster), and a run with nothing to render reaches no cluster. `notes` hears what the
    workers say about their engine (Session)."""

    def __init__(self, target, notes=None):
        self.target, self.notes, self._session, self._stack = target, notes, None, contextlib.ExitStack()

    def session(self) -> Session:
        if self._session is None:
            self._session = self._stack.enter_context(Session(self.target, self.notes))
        return self._session

    def __enter__(self) -> Reach:
        return self

    def __exit__(self, *exc) -> None:
        self._stack.close()


def bundle(loaded) -> Bundle:
    """The files a loaded scene was built from (api.loading.Loaded, loaded with its files kept)."""
    return Bundle.of(loaded.path, loaded.kept)


def still(reach: Reach, loaded, job, progress=None, changes: dict | None = None):
    """(image, stats): the loaded frame's image (or ids) traced on the cluster, tile groups as tasks."""
    stats, (tiles, traced) = Stats(), plan(loaded.scene, job)
    results = reach.session().tiles(bundle(loaded), changes or {}, loaded.frame, job, traced, tiles,
                                    1 if job.signature else loaded.scene.settings.samples)
    return assemble(job, len(tiles), results, stats, progress), stats


def frames(reach: Reach, loaded, todo: list[int], job, changes: dict, progress=None):
    """(frame, image, stats) of each frame to do, a frame a task, as they finish."""
    for done, result in enumerate(reach.session().frames(bundle(loaded), changes, todo, job), 1):
        if progress:
            progress(done, len(todo))
        yield result
