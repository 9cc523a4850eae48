"""Signals and dying workers, on a real multi-worker render in a subprocess.

Each test starts `rtcli render` in a session of its own (so its process group can
be signalled as a terminal's Ctrl-C would), waits until the workers are busy,
sends a signal and checks: the exit code, the time to exit (a generous bound:
the machine is shared), one error line, no output or temporary file, and no
process left in the group or with the render as parent.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from helpers import SLOW, scene_from_yaml

from rtcli.kernels import variants
from rtcli.errors import Interrupted
from rtcli.rendering.tiles import PART_RAYS, PART_SECONDS, Job, render, trace_in_parts
from rtcli.stats import Stats

pytestmark = pytest.mark.skipif(not os.path.exists("/proc/self/task"), reason="needs Linux's /proc")



def _children(pid: int) -> list[int]:
    with open(f"/proc/{pid}/task/{pid}/children") as f:
        return [int(x) for x in f.read().split()]


def _group_members(pgid: int) -> list[int]:
    """Processes whose process group is pgid, or whose parent is pgid."""
    found = []
    for name in os.listdir("/proc"):
        try:
            with open(f"/proc/{name}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pgid or int(fields[2]) == pgid:          # ppid, pgrp
            found.append(int(name))
    return found


def _start(tmp_path, workers: int) -> subprocess.Popen:
    (tmp_path / "slow.yaml").write_text(SLOW)
    proc = subprocess.Popen([sys.executable, "-m", "rtcli", "render", "slow.yaml", "--engine", "numpy",
                             "--workers", str(workers), "-o", "out.png"],
                            cwd=tmp_path, stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.monotonic() + 30
    while len(_children(proc.pid)) < workers - (workers == 1) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)                      # the scene is loaded and tiles are being traced
    assert proc.poll() is None, proc.stderr.read()
    return proc


def _stop(proc, send) -> tuple[int, float, str]:
    start = time.monotonic()
    send()
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)           # leave nothing running when the test fails
        proc.wait()
        raise
    return proc.returncode, time.monotonic() - start, err.decode()


def _nothing_left(tmp_path, proc) -> None:
    time.sleep(0.2)
    assert _group_members(proc.pid) == []
    assert sorted(os.listdir(tmp_path)) == ["slow.yaml"]


@pytest.mark.parametrize("target, signum, code", [
    ("group", signal.SIGINT, 130),       # Ctrl-C in a terminal
    ("parent", signal.SIGINT, 130),
    ("group", signal.SIGTERM, 143),
    ("parent", signal.SIGTERM, 143),
])
def test_signal_stops_a_multi_worker_render_at_once(tmp_path, target, signum, code):
    proc = _start(tmp_path, workers=2)
    send = (lambda: os.killpg(proc.pid, signum)) if target == "group" else (lambda: os.kill(proc.pid, signum))
    returncode, seconds, err = _stop(proc, send)
    assert (returncode, err) == (code, "error: interrupted\n")
    assert seconds < 10
    _nothing_left(tmp_path, proc)


def test_signal_stops_a_single_worker_render(tmp_path):
    proc = _start(tmp_path, workers=1)
    returncode, seconds, err = _stop(proc, lambda: os.killpg(proc.pid, signal.SIGINT))
    assert (returncode, err, seconds < 10) == (130, "error: interrupted\n", True)
    _nothing_left(tmp_path, proc)


def test_a_killed_worker_ends_the_render_with_one_line(tmp_path):
    """A worker killed as the out-of-memory killer would: exit 2, one line naming it, no traceback."""
    proc = _start(tmp_path, workers=2)
    worker = _children(proc.pid)[0]
    returncode, seconds, err = _stop(proc, lambda: os.kill(worker, signal.SIGKILL))
    assert returncode == 2 and seconds < 10
    assert err == "error: a worker process was killed by SIGKILL (out of memory?); the render was stopped\n"
    _nothing_left(tmp_path, proc)


@pytest.mark.skipif(not hasattr(signal, "pthread_kill"), reason="POSIX threads' signals")
def test_ctrl_c_while_tiles_are_submitted_waits_until_every_tile_is(monkeypatch):
    """Ctrl-C inside the pool's submit could leave a lock of its queues held and hang the exit; it
    is held back until the tiles are all submitted, then stops the render (pool.held_signals)."""
    scene = scene_from_yaml("camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nobjects: [{sphere: {}}]\n")
    submitted, real_submit = [], ProcessPoolExecutor.submit

    def submit(pool, *args, **kwargs):
        submitted.append(1)
        if len(submitted) == 3:                          # Ctrl-C arrives in the middle of submitting
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
            time.sleep(0.01)
        return real_submit(pool, *args, **kwargs)

    def interrupted(signum, frame):
        raise Interrupted(signum)
    monkeypatch.setattr(ProcessPoolExecutor, "submit", submit)
    previous = signal.signal(signal.SIGINT, interrupted)
    try:
        with pytest.raises(Interrupted):
            render(scene, Job(32, 32, tile=8), workers=2)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(submitted) == 16


HEAVY = (SLOW.replace("width: 320, height: 240", "width: 1600, height: 1600")   # one tile of minutes
         .replace("max_depth: 6", "max_depth: 8"))                             # with --engine compiled


@pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")
@pytest.mark.parametrize("target, signum, code, workers", [
    ("group", signal.SIGTERM, 143, 1),
    ("parent", signal.SIGINT, 130, 1),
    ("parent", signal.SIGTERM, 143, 2),
])
def test_signal_stops_a_render_inside_one_long_compiled_tile(tmp_path, target, signum, code, workers):
    """The whole image is one tile, traced in machine code, where Python cannot run a signal's
    handler; the tile is traced in parts, so the render still ends at once."""
    (tmp_path / "slow.yaml").write_text(HEAVY)
    proc = subprocess.Popen([sys.executable, "-m", "rtcli", "render", "slow.yaml", "--engine", "compiled",
                             "--tile", "4096", "--workers", str(workers), "-o", "out.png"],
                            cwd=tmp_path, stderr=subprocess.PIPE, start_new_session=True)
    time.sleep(4.0)                      # loaded (machine code, or numba's cache) and tracing the tile
    assert proc.poll() is None, proc.stderr.read()
    send = (lambda: os.killpg(proc.pid, signum)) if target == "group" else (lambda: os.kill(proc.pid, signum))
    returncode, seconds, err = _stop(proc, send)
    assert (returncode, err) == (code, "error: interrupted\n")
    assert seconds < 5                   # a part takes about 0.1 s; without parts, the rest of the tile
    _nothing_left(tmp_path, proc)


class Engine:
    """A compiled engine's stand-in: each ray's color from its coordinates, 20 µs a ray."""

    def __init__(self):
        self.parts = []

    def trace_pixels(self, cam, x, y, nc, nr, stats):
        self.parts.append(len(x))
        time.sleep(20e-6 * len(x))
        stats.primary += 0
        stats.reflected += len(x)
        return np.column_stack([x, y, x * nc + y])


def test_a_compiled_tile_is_traced_in_parts_of_a_tenth_of_a_second():
    engine, stats = Engine(), Stats()
    x, y = np.arange(40_000) % 200 + 0.5, np.arange(40_000) // 200 + 0.5
    colors = trace_in_parts(engine, None, x, y, Job(200, 200), stats)
    np.testing.assert_array_equal(colors, np.column_stack([x, y, x * 200 + y]))
    assert stats.reflected == 40_000 and sum(engine.parts) == 40_000 and engine.parts[0] == PART_RAYS
    assert 5 < len(engine.parts) < 40 and max(engine.parts) <= 2 * PART_SECONDS / 20e-6
    assert all(b <= 2 * a for a, b in zip(engine.parts, engine.parts[1:]))
