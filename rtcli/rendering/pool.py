"""Stopping the render's worker processes at once, and naming why one died.

A render's tiles go to a pool of forked worker processes (render.py). Workers
ignore SIGINT, so Ctrl-C in a terminal (sent to the whole process group) reaches
only the parent, which then stops them all: pending tiles are cancelled and the
workers killed, so the command ends within a moment instead of finishing every
queued tile. A worker also dies with its parent (Linux's PR_SET_PDEATHSIG), so no
worker outlives a parent that was killed outright.
"""

from __future__ import annotations

import contextlib
import ctypes
import signal
import threading
import time

from rtcli.errors import Interrupted, RtcliError

PR_SET_PDEATHSIG = 1
HELD = {signal.SIGINT, signal.SIGTERM}          # the signals that stop a render (cli.py)


@contextlib.contextmanager
def held_signals():
    """SIGINT and SIGTERM held pending while the block runs, then delivered.

    Submitting tiles takes locks of the pool's queues that its manager thread also
    takes; Ctrl-C raised inside a submit can leave one locked, and the exit, which
    joins that thread, would then wait forever. Submitting takes milliseconds. The
    pool's threads, started by the first submit, keep the signals held, so the main
    thread is the one that takes them afterwards.
    """
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextlib.contextmanager
def interrupted_once():
    """While the block runs (a pool's life, its stop included), the first SIGINT or SIGTERM goes to
    the handler that was there (the command line's raises Interrupted, Python's KeyboardInterrupt)
    and any later one is ignored. A second signal (Ctrl-C, then a supervisor's SIGTERM) would
    otherwise raise again while the first unwinds: half way through the release of a lock of
    threading (`RuntimeError: release unlocked lock`), or through the pool's shutdown, with a
    traceback or a hang. Stopping the pool is bounded (stop_pool), so ignoring is safe."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.getsignal(s) for s in HELD}
    wrapped = {s: h for s, h in previous.items() if callable(h)}
    fired: list[int] = []

    def once(signum, frame):
        if not fired:
            fired.append(signum)
            wrapped[signum](signum, frame)
    for s in wrapped:
        signal.signal(s, once)
    try:
        yield
    finally:
        for s, h in wrapped.items():
            signal.signal(s, h)


def watch_worker() -> None:
    """In a worker: ignore SIGINT (the parent handles it), take SIGTERM again (it was forked while
    the parent held it) and die when the parent dies. SIGTERM ends a worker at once, by its
    default action: the handler forked from the parent (cli.py's, which raises Interrupted) would
    print a traceback from the worker when the signal came while it starts or waits for a tile;
    the parent reports the death as the interrupt it is (worker_died)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):            # not Linux: the parent's stop_pool still applies
        pass


def _processes(pool) -> list:
    return list((getattr(pool, "_processes", None) or {}).values())


def stop_pool(pool, finished: bool) -> None:
    """Shut the pool down; unless every tile is done, cancel the rest and kill the workers first.

    Either way the pool's manager thread has ended on return (within a bound when the workers
    were killed). Left running, it closes its wake-up pipe while the interpreter's exit
    (concurrent.futures' _python_exit, which takes no lock) may be writing to it: an
    `OSError: [Errno 9] Bad file descriptor` traceback after rtcli's own `error: interrupted`,
    now and then, when a signal reached the parent alone.
    """
    if finished:
        pool.shutdown(wait=True)
        return
    workers = _processes(pool)
    for p in workers:
        if p.exitcode is None:
            p.kill()
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    for p in workers:
        p.join(timeout=5)
    if manager is not None:
        manager.join(timeout=5)                 # the workers are dead: it sees the pool broken and ends


def _exit_codes(workers: list, wait: float = 1.0) -> list[int]:
    """The non-zero exit codes of the workers, waiting a moment for the one that died to be reaped.

    The pool can learn of a death (a half-written result) a moment before the
    kernel reports the dead process's status; the codes other than SIGTERM's are
    the informative ones (the pool terminates the survivors with SIGTERM).
    """
    deadline = time.monotonic() + wait
    while True:
        codes = [p.exitcode for p in workers if p.exitcode not in (None, 0)]
        if any(c != -signal.SIGTERM for c in codes) or time.monotonic() > deadline:
            return codes
        time.sleep(0.01)


def worker_died(pool) -> BaseException:
    """What to raise when a worker died mid-render: Interrupted when SIGTERM or SIGINT killed it
    (the whole process group was signalled), else an RtcliError naming the signal or exit code."""
    codes = _exit_codes(_processes(pool))
    signals = [-c for c in codes if c < 0]
    if signals and all(s in (signal.SIGTERM, signal.SIGINT) for s in signals):
        return Interrupted(signals[0])
    killer = next((s for s in signals if s not in (signal.SIGTERM, signal.SIGINT)), None)
    if killer is not None:
        hint = " (out of memory?)" if killer == signal.SIGKILL else ""
        what = f"was killed by {signal.Signals(killer).name}{hint}"
    elif codes:
        what = f"exited with code {codes[0]}"
    else:
        what = "died unexpectedly (killed, or out of memory)"
    return RtcliError(f"a worker process {what}; the render was stopped")
