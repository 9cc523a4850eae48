"""`rtcli warmup --cluster`: the engine warmed on every worker of a cluster at once (Client.run),
each in a thread of its own so that the worker keeps answering the scheduler while it compiles;
a line for each worker: already warm, compiled in N s, or why it failed.
"""

from __future__ import annotations

import asyncio
import time

from rtcli.cluster.notes import Told
from rtcli.cluster.software import fingerprint, mismatch
from rtcli.cluster.target import connect_timeout
from rtcli.errors import RtcliError
from rtcli.rendering import warmup as warming


async def warm_here(client: dict, dask_worker=None) -> dict:
    """Client.run's function: this worker's engine warmed (_warm) in a thread, while the worker's
    event loop goes on answering the scheduler."""
    return await asyncio.to_thread(_warm, client, Told(dask_worker))


def _warm(client: dict, notes: Told) -> dict:
    """_warmed, and "told": how many notes it sent (warm waits until the client heard them)."""
    return {**_warmed(client, notes), "told": notes.sent}


def _warmed(client: dict, notes: Told) -> dict:
    """rtcli.rendering.warmup here, for a client whose software is this worker's, its notes told to
    the client: {"parts": [(what, compile seconds)], "seconds": in all, "why": why a machine code
    file is missing}, or {"failed": why}."""
    start = time.perf_counter()
    if (refusal := mismatch(client, fingerprint(), notes.worker.address)) is not None:
        return {"failed": str(refusal)}
    try:
        done, (_, why) = warming.warmup(notes=notes)
    except RtcliError as e:
        return {"failed": str(e)}
    warming.bytecode()
    return {"parts": [(what, load.compile_seconds) for what, load in done], "why": why,
            "seconds": time.perf_counter() - start}


def warm(session, echo) -> None:
    """Warm every worker of a cluster.Session at once, and `echo` a line for each, by address;
    RtcliError, in one line, naming the workers that could not be warmed (after the others' lines)."""
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
