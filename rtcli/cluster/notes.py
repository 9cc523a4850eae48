"""What a cluster's workers say about their engine (README.md, "Clusters"), told to the client
while it happens.

A worker without compiled code at hand compiles the engine the first time a task needs it, for a
minute or more, and the tasks waiting on it finish nothing meanwhile. So a worker tells what its
engine is doing as it happens: each note the engine's start-up makes on a worker ("compiling
the render engine, once", "compiled in 92.1 s") goes to the scheduler as a Dask event on TOPIC,
tagged with the worker's address, and the seconds it compiled go the same way once the engine is
ready. The client subscribes to the topic when it connects: it passes every note on at once, above
its progress bar, and after a render says which workers compiled and for how long (Heard).
"""

from __future__ import annotations

import threading

TOPIC = "rtcli-engine"               # the Dask event topic of the workers' engine notes


# --- on a worker ---
class Told:
    """A worker's notes about its engine (loading.ready's `notes`), sent to the clients as they happen;
    `sent` counts them."""

    def __init__(self, worker):
        self.worker, self.sent = worker, 0

    def __call__(self, text: str) -> None:
        self._send(note=text)

    def compiled(self, seconds: float) -> None:
        """After the engine is ready: the seconds it spent compiling, if any (the client's summary)."""
        if seconds > 0:
            self._send(compiled=round(seconds, 3))

    def _send(self, **msg) -> None:
        self.worker.log_event(TOPIC, {"worker": self.worker.address, **msg})      # safe from any thread
        self.sent += 1


def told() -> Told | None:
    """The notes of the worker running this task; None off a worker (the notes then go to stderr)."""
    try:
        from distributed import get_worker  # the cluster extra: only on a worker
        return Told(get_worker())
    except (ImportError, ValueError):
        return None


# --- on the client ---
class Heard:
    """What the workers tell about their engine during a session (a Client.subscribe_topic handler):
    each note passed on at once to `notes`, and the seconds each worker compiled, for summary()."""

    def __init__(self, notes):
        self.notes, self.compiling, self.counts = notes, {}, {}
        self._changed = threading.Condition()

    def __call__(self, event) -> None:
        try:
            _, msg = event
            worker = msg["worker"]
            if "note" in msg:
                self.notes(f"worker {worker}: {msg['note']}")
            if "compiled" in msg:
                self.compiling[worker] = self.compiling.get(worker, 0.0) + float(msg["compiled"])
        except Exception:          # runs in Dask's event loop: a malformed event must not stop the client
            return
        with self._changed:
            self.counts[worker] = self.counts.get(worker, 0) + 1
            self._changed.notify_all()

    def wait(self, sent: dict, timeout: float) -> None:
        """Until the notes `sent` ({worker: how many}) have all been heard, or `timeout` seconds: they
        come through the scheduler by another way than a Client.run's answer, and may come later."""
        with self._changed:
            self._changed.wait_for(lambda: all(self.counts.get(w, 0) >= n for w, n in sent.items()), timeout)

    def summary(self) -> None:
        """A note for each worker that compiled since the last summary, with how long it took."""
        compiling, self.compiling = self.compiling, {}
        for worker, seconds in sorted(compiling.items()):
            self.notes(f"worker {worker} compiled the engine in {seconds:.1f} s (cached there for later renders)")
