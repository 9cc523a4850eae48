"""The compiled engine on a cluster's workers (README.md, "Clusters"): its start-up told to the client
while it happens, and `rtcli warmup --cluster`.

A worker without compiled code at hand compiles the engine the first time a task needs it, for a
minute or more, and the tasks waiting on it finish nothing meanwhile. So a worker tells what its
engine is doing as it happens: each note rtcli.compiled.loading.ready makes on a worker ("compiling
the render engine, once", "compiled in 92.1 s") goes to the scheduler as a Dask event on TOPIC,
tagged with the worker's address, and the seconds it compiled go the same way once the engine is
ready. The client subscribes to the topic when it connects: it passes every note on at once, above
its progress bar, and after a render says which workers compiled and for how long (Heard).

`rtcli warmup --cluster` runs rtcli.compiled.warmup on every worker at once (Client.run), each in a
thread of its own so that the worker keeps answering the scheduler while it compiles, and reports
each worker: already warm, compiled in N s, or why it failed.

distributed is imported only by the code that runs on a cluster.
"""

from __future__ import annotations

import threading

from rtcli.errors import RtcliError

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
        from distributed import get_worker
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


# --- rtcli warmup --cluster ---
async def warm_here(client: dict, dask_worker=None) -> dict:
    """Client.run's function: this worker's engine warmed (_warm) in a thread, while the worker's
    event loop goes on answering the scheduler."""
    import asyncio
    return await asyncio.to_thread(_warm, client, Told(dask_worker))


def _warm(client: dict, notes: Told) -> dict:
    """_warmed, and "told": how many notes it sent (warm waits until the client heard them)."""
    return {**_warmed(client, notes), "told": notes.sent}


def _warmed(client: dict, notes: Told) -> dict:
    """rtcli.compiled.warmup here, for a client whose software is this worker's, its notes told to
    the client: {"parts": [(what, compile seconds)], "seconds": in all, "why": why a machine code
    file is missing}, or {"failed": why}."""
    import time

    from rtcli.cluster import fingerprint, mismatch
    from rtcli.compiled.warmup import bytecode, warmup
    start = time.perf_counter()
    if (refusal := mismatch(client, fingerprint(), notes.worker.address)) is not None:
        return {"failed": str(refusal)}
    try:
        done, (_, why) = warmup(notes=notes)
    except RtcliError as e:
        return {"failed": str(e)}
    bytecode()
    return {"parts": [(what, load.compile_seconds) for what, load in done], "why": why,
            "seconds": time.perf_counter() - start}


def warm(session, echo) -> None:
    """Warm every worker of a cluster.Session at once, and `echo` a line for each, by address;
    RtcliError, in one line, naming the workers that could not be warmed (after the others' lines)."""
    from rtcli.cluster import connect_timeout, fingerprint
    found = session.run(warm_here, fingerprint())
    session.heard.wait({w: r["told"] for w, r in found.items() if isinstance(r, dict) and "told" in r},
                       connect_timeout())
    failed = []
    for address, result in sorted(found.items()):
        if isinstance(result, dict) and "parts" in result:
            echo(f"{address}: {_outcome(result)}")
        else:
            failed.append((address, _failure(result)))
    if len(found) == 1 and failed:
        raise RtcliError(f"the worker {failed[0][0]} could not be warmed: {failed[0][1]}")
    if failed:
        raise RtcliError(f"{len(failed)} of {len(found)} workers could not be warmed: " +
                         "; ".join(f"{address}: {why}" for address, why in failed))
    compiled = sum(1 for r in found.values() if any(c for _, c in r["parts"]))
    echo(f"{_workers(len(found))} warm, {compiled} of them compiled" if compiled else
         f"{_workers(len(found))} warm, none compiled")


def _workers(n: int) -> str:
    return f"{n} worker" if n == 1 else f"{n} workers"


def _outcome(result: dict) -> str:
    """A warmed worker's line: compiled in N s (each part's seconds) or already warm; why a machine
    code file could not be written."""
    compiled, seconds = [(what, c) for what, c in result["parts"] if c], result["seconds"]
    if compiled:
        each = ", ".join(f"{what} {c:.1f} s" for what, c in compiled)
        line = f"compiled in {sum(c for _, c in compiled):.1f} s ({each}), ready in {seconds:.1f} s"
    else:
        line = f"already warm (loaded in {seconds:.2f} s)"
    if result.get("why"):
        line += f"; machine code files not written: {result['why']}"
    return line


def _failure(result) -> str:
    if isinstance(result, dict) and "failed" in result:
        return result["failed"]
    if isinstance(result, BaseException):
        return f"{type(result).__name__}: {result}"
    return f"an answer rtcli does not know ({type(result).__name__})"
