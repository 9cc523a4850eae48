"""No traceback after `error: interrupted`, however a signal arrives (rtcli/rendering/pool.py).

Two races, each made certain here rather than left to timing (tests/rendering/test_signals.py runs
real renders): the interpreter's exit writing to the wake-up pipe of a pool whose manager
thread is closing it, and SIGTERM reaching a worker that still has the parent's handler.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

pytestmark = pytest.mark.skipif(os.name != "posix", reason="fork and POSIX signals")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)


def test_a_stopped_pool_leaves_the_exit_nothing_to_race():
    """The exit's unlocked wake-up (concurrent.futures' _python_exit) is slowed so it always meets
    the manager thread closing the pipe, as a signal to the parent alone sometimes made it: with
    the thread ended by stop_pool there is nothing to meet (before: `OSError: handle is closed`
    or `[Errno 9] Bad file descriptor` on stderr, every time)."""
    done = run("""
        import multiprocessing, threading, time
        import concurrent.futures.process as cfp
        from concurrent.futures import ProcessPoolExecutor
        from rtcli.rendering.pool import stop_pool

        def wakeup(self):
            if not self._closed:
                if threading.current_thread() is threading.main_thread():
                    time.sleep(0.3)
                self._writer.send_bytes(b"")
        cfp._ThreadWakeup.wakeup = wakeup

        def work(x):
            time.sleep(10)

        if __name__ == "__main__":
            pool = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork"))
            futures = [pool.submit(work, k) for k in range(8)]
            time.sleep(0.2)
            stop_pool(pool, False)
            print("stopped")
    """)
    assert (done.returncode, done.stdout, done.stderr) == (0, "stopped\n", "")


def test_sigterm_ends_a_starting_worker_without_a_word():
    """A worker is forked with the parent's SIGTERM handler (which raises Interrupted) and the
    signal held; one pending when watch_worker lets it in ends the worker by SIGTERM's default
    action, not by a traceback ('Exception in initializer')."""
    done = run("""
        import os, signal
        from rtcli.errors import Interrupted
        from rtcli.rendering.pool import watch_worker

        def interrupted(signum, frame):
            raise Interrupted(signum)
        signal.signal(signal.SIGTERM, interrupted)
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
        os.kill(os.getpid(), signal.SIGTERM)
        watch_worker()
        print("survived")
    """)
    assert (done.returncode, done.stdout, done.stderr) == (-signal.SIGTERM, "", "")


def test_while_a_pool_runs_only_the_first_signal_is_handled():
    """interrupted_once: the handler that was there takes the first SIGINT or SIGTERM; a second,
    of either kind, is ignored until the block ends, then the handlers are as they were."""
    from rtcli.rendering.pool import interrupted_once
    seen = []

    def handler(signum, frame):
        seen.append(signum)
    before = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with interrupted_once():
            os.kill(os.getpid(), signal.SIGINT)
            os.kill(os.getpid(), signal.SIGTERM)
            os.kill(os.getpid(), signal.SIGINT)
        assert seen == [signal.SIGINT]
        assert signal.getsignal(signal.SIGINT) is handler and signal.getsignal(signal.SIGTERM) is handler
        os.kill(os.getpid(), signal.SIGTERM)
        assert seen == [signal.SIGINT, signal.SIGTERM]
    finally:
        for s, h in before.items():
            signal.signal(s, h)


@pytest.mark.parametrize("gap", [0.0, 0.002, 0.02])
def test_ctrl_c_then_sigterm_to_the_group_ends_with_one_line(tmp_path, gap):
    """A Ctrl-C to the parent, then a supervisor's SIGTERM to the group while the first unwinds
    (before: a traceback or a hang in about half the runs)."""
    from test_signals import _nothing_left, _start, _stop
    proc = _start(tmp_path, workers=2)

    def send():
        os.kill(proc.pid, signal.SIGINT)
        time.sleep(gap)
        os.killpg(proc.pid, signal.SIGTERM)
    returncode, seconds, err = _stop(proc, send)
    assert returncode in (130, 143) and err == "error: interrupted\n" and seconds < 10
    _nothing_left(tmp_path, proc)
