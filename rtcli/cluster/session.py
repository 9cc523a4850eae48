"""A connection to the cluster for one command (the client's side): the workers checked, the
scene sent as its files, tiles and frames submitted as tasks and their results taken as they
finish; Dask's own log lines kept off the terminal."""

from __future__ import annotations

import contextlib
import logging
import math
import signal
import threading
import warnings

from rtcli.cluster.bundle import Bundle
from rtcli.cluster.leftout import LeftOut, survey
from rtcli.cluster.notes import TOPIC, Heard
from rtcli.cluster.probe import Clock, deadline, probe
from rtcli.cluster.software import fingerprint
from rtcli.cluster.target import Target, load_distributed
from rtcli.cluster.tasks import blob, frame_task, tiles_task
from rtcli.compiled.loading import say
from rtcli.errors import RtcliError, shown

RAYS_PER_TASK = 2_000_000         # primary rays a task traces, at most (unless that leaves workers idle)


TASKS_PER_WORKER = 4              # at least this many tasks a worker thread, so all finish together


# --- on the client ---
def groups(tiles: list, samples: int, threads: int) -> list[list]:
    """Consecutive tiles in groups of about RAYS_PER_TASK primary rays, at least TASKS_PER_WORKER
    groups per worker thread (as many as there are tiles, at most)."""
    rays = sum(len(r) * len(c) for r, c in tiles) * samples ** 2
    n = min(len(tiles), max(math.ceil(rays / RAYS_PER_TASK), TASKS_PER_WORKER * max(threads, 1)))
    size = len(tiles) / n
    return [tiles[round(k * size):round((k + 1) * size)] for k in range(n)]


class Session:
    """A connection to the cluster for one command: `with Session(target) as s: ...`. `notes` hears
    what the workers say about their engine, as they say it (default: stderr; cluster_engine.Heard)."""

    def __init__(self, where: Target, notes=None):
        self.where, self.client, self.cluster, self.futures = where, None, None, []
        self.heard, self.left_out, self.made, self.deadline = Heard(notes or say), None, {}, None
        self._quiet = contextlib.ExitStack()

    def __enter__(self) -> Session:
        distributed = load_distributed()
        self.deadline = deadline(self.where.timeout)         # Dask's configuration is there once it is imported
        self._quiet.enter_context(_quiet())
        try:
            self._connect(distributed)
            self.client.subscribe_topic(TOPIC, self.heard)       # before any task: no note is missed
            self._check_workers()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _connect(self, distributed) -> None:
        if self.where.local:
            with _sigint_ignored():              # the workers leave Ctrl-C to this process, which stops them
                self.cluster = distributed.LocalCluster(
                    n_workers=self.where.local, threads_per_worker=1, processes=True, host="127.0.0.1",
                    dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
            self.client = distributed.Client(self.cluster, set_as_default=False)
            return
        clock = Clock(self.deadline)
        probe(self.where.address, self.deadline, distributed)      # a Dask scheduler, or one line
        try:
            self.client = distributed.Client(self.where.address, set_as_default=False,
                                             timeout=max(clock.left(), 1.0))
        except (OSError, TimeoutError, ValueError) as e:
            raise RtcliError(f"cannot reach the Dask scheduler at {shown(self.where.address)}: "
                             f"{' '.join(str(e).split())}") from None

    def _check_workers(self) -> None:
        """Wait a while for a first worker; leave out the workers that cannot run this rtcli or run
        other software (leftout.py), or refuse the cluster if no other worker is left."""
        distributed = load_distributed()
        try:
            self.client.wait_for_workers(1, timeout=self.deadline)
        except (TimeoutError, distributed.TimeoutError):
            raise RtcliError(f"{self.where} has no workers (start some: README.md, Clusters)") from None
        try:
            found = survey(self.client)
        except Exception as e:            # the cluster could not be asked
            raise RtcliError(f"the workers of {self.where} cannot run rtcli ({type(e).__name__}: {e}); install "
                             "the same rtcli and libraries on every worker") from None
        refusals = [why for why in found.values() if why is not None]
        if found and len(refusals) == len(found):
            raise refusals[0]
        self.left_out = LeftOut(self.client, self.heard.notes)
        self.left_out.add(found)

    @property
    def threads(self) -> int:
        return sum(self.client.nthreads().values())

    def __exit__(self, *exc) -> None:
        try:
            if self.client is not None:
                with contextlib.suppress(Exception):
                    self.client.cancel(self.futures)
                with contextlib.suppress(Exception):
                    self.client.close(timeout=5)
            if self.cluster is not None:
                with contextlib.suppress(Exception):
                    self.cluster.close(timeout=5)
        finally:
            self._quiet.close()

    # --- work ---
    def send(self, bundle: Bundle, overrides: dict) -> tuple[dict, dict]:
        """(spec, blobs): what every task needs to build the scene; each file a task of its own,
        keyed by its content."""
        blobs = {digest: self.client.submit(blob, data, key=f"rtcli-file-{digest}", pure=False)
                 for digest, data in bundle.blobs.items()}
        spec = {"key": bundle.key, "scene_path": bundle.scene_path, "manifest": bundle.manifest,
                "overrides": overrides, "fingerprint": fingerprint()}
        return spec, blobs

    def tiles(self, bundle: Bundle, overrides: dict, frame: int, job, traced: int, tiles: list, samples: int):
        """The results of every tile, group by group as they finish."""
        spec, blobs = self.send(bundle, overrides)
        self.futures = [self._submit(tiles_task, spec, blobs, frame, job, traced, group)
                        for group in groups(tiles, samples, self.threads)]
        for results in self._finished():
            yield from results

    def frames(self, bundle: Bundle, overrides: dict, frames: list[int], job):
        """(frame, image, stats) of each frame, as they finish."""
        spec, blobs = self.send(bundle, overrides)
        self.futures = [self._submit(frame_task, spec, blobs, k, job, priority=-k) for k in frames]
        yield from self._finished()

    def run(self, function, *args) -> dict:
        """`function(*args)` on every worker at once (Client.run): {worker address: its result, or the
        exception it raised}. The workers' notes are heard from the start: Client.run's request
        may overtake the subscription to them (tasks travel behind it, on the same stream), so a
        task goes first, and once it is done the scheduler holds the subscription."""
        distributed = load_distributed()
        try:
            self.client.submit(blob, b"", pure=False).result()
            return self.client.run(function, *args, on_error="return")
        except (distributed.CancelledError, OSError) as e:
            raise RtcliError(f"lost {self.where} ({type(e).__name__})") from None

    def _submit(self, function, *args, priority: int = 0, tries: int = 1, workers=None):
        """A task of this command, remembered so that it can be submitted again (_again)."""
        future = self.client.submit(function, *args, pure=False, priority=priority, workers=workers,
                                    allow_other_workers=workers is not None)
        self.made[future.key] = (function, args, priority, tries)
        return future

    def _again(self, future):
        """The failed task `future` submitted again, to the workers not left out, when a worker
        refused it or one that would is found now (leftout.py); else None."""
        function, args, priority, tries = self.made[future.key]
        workers = self.left_out.again(future.exception(), tries)
        if workers is None:
            return None
        del self.made[future.key]
        future.release()
        return self._submit(function, *args, priority=priority, tries=tries + 1, workers=workers)

    def _finished(self):
        """The futures' results as they finish (a task that a worker refused, again elsewhere); then
        which workers compiled the engine meanwhile."""
        distributed = load_distributed()
        try:
            running = distributed.as_completed(self.futures, loop=self.client.loop)
            for future in running:
                if future.status == "error" and (again := self._again(future)) is not None:
                    self.futures.append(again)
                    running.add(again)
                    continue
                yield future.result()
                self.made.pop(future.key, None)
                future.release()
            self.heard.summary()
        except distributed.KilledWorker as e:
            raise RtcliError(f"a task of this render kept killing its workers (out of memory?): {e}") from None
        except (distributed.CancelledError, OSError) as e:
            raise RtcliError(f"lost {self.where} mid-render ({type(e).__name__}); the render was stopped") \
                from None
        except RtcliError:
            raise
        except Exception as e:           # a failure on a worker: shown in one line
            raise RtcliError(f"a worker failed: {type(e).__name__}: {e}") from None


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored meanwhile, so that processes started inside the block inherit it ignored (Python
    keeps an ignored SIGINT ignored): Ctrl-C at a terminal signals the whole process group."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def _quiet():
    """Dask's log lines and warnings (a worker restarted, a large graph) stay off the terminal:
    rtcli speaks in one line."""
    handlers = logging.getLogger("distributed").handlers       # Dask's own, fed by all its loggers
    levels = [h.level for h in handlers]
    for h in handlers:
        h.setLevel(logging.CRITICAL + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            yield
        finally:
            for h, level in zip(handlers, levels):
                h.setLevel(level)
