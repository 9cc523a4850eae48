"""Workers left out of a render (docs/cluster.md, "Workers with other software"): a `dask worker`
process whose rtcli reports other sources, or that has no rtcli at all, joins a cluster before
or during a render; it is named in one note, its tasks run on the other worker, and the image
is the local render's. Only a cluster with no other worker is refused.

The good worker is a thread of this process (its tasks can be held until the other worker has
joined and refused one); the other is a process started with a preload script that changes
what rtcli reports there.
"""

from __future__ import annotations

import logging
import subprocess
import sys
import threading

import pytest
from helpers import CLUSTER_SCENE

from rtcli.api.loading import load_file
from rtcli.cluster import renders, software
from rtcli.cluster import session as sessions
from rtcli.cluster.target import Target
from rtcli.errors import RtcliError
from rtcli.rendering import tiles as tiling
from rtcli.rendering.tiles import Job, render

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.slow   # Dask schedulers and worker processes

SCENE = CLUSTER_SCENE
OTHER_SOURCES = """\
from rtcli.cluster import software
ours = software.fingerprint()
software._fingerprint = dict(ours, rtcli=ours["rtcli"].split(" (")[0] + " (sources 000000000000)")
"""
NO_RTCLI = "import sys\nsys.modules['rtcli'] = None\n"
WAIT = 60                         # seconds a test waits for a worker process to join or to be left out


@pytest.fixture
def cluster():
    """One worker, a thread of this process, on loopback TCP."""
    c = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                 host="127.0.0.1", dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    yield c
    c.close()


@pytest.fixture
def joining(tmp_path):
    """start(scheduler, preload text): a `dask worker` process joining that scheduler, its rtcli
    changed by the preload; stopped at the end of the test."""
    started = []

    def start(address: str, preload: str):
        script = tmp_path / f"preload{len(started)}.py"
        script.write_text(preload)
        started.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--no-nanny",
             "--no-dashboard", "--host", "127.0.0.1", "--preload", str(script)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    yield start
    for process in started:
        process.terminate()
        try:
            process.wait(3)                # a worker whose scheduler has gone waits for it: not worth it
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(20)


@pytest.fixture
def loaded(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.yaml").write_text(SCENE)
    monkeypatch.setattr(sessions, "RAYS_PER_TASK", 50)          # a task a tile or so: many tasks
    return load_file("scene.yaml", keep=True)


def left_out_note(notes: list, good: str) -> str:
    """The one note naming a worker left out (not `good`); its address."""
    named = [text for text in notes if text.endswith("(left out: the other workers take its tasks)")]
    assert len(named) == 1, notes
    address = named[0].split()[2]
    assert address.startswith("tcp://127.0.0.1:") and address != good
    return address


def test_a_worker_with_other_sources_joining_mid_render_is_left_out(cluster, joining, loaded, monkeypatch):
    """The good worker's first task holds until the other worker has joined and refused a task; the
    render then ends on the good worker: the local render's bytes, and one note naming the other."""
    expected = render(loaded.scene, Job(24, 16))[0]
    good = next(iter(cluster.scheduler_info["workers"]))
    notes, left, real, started = [], threading.Event(), tiling.run_tiles, []

    def note(text):
        notes.append(text)
        if "(left out: " in text:
            left.set()

    def held(*args, **kw):
        if not started:
            started.append(joining(cluster.scheduler_address, OTHER_SOURCES))
            left.wait(WAIT)
        return real(*args, **kw)
    monkeypatch.setattr(tiling, "run_tiles", held)
    with renders.Reach(Target(cluster.scheduler_address, timeout=10), note) as reach:
        image, _ = renders.still(reach, loaded, Job(24, 16, tile=4))
    assert left.is_set(), notes
    assert image.tobytes() == expected.tobytes()
    other, ours = left_out_note(notes, good), software.fingerprint()["rtcli"]
    assert notes == [f"the worker {other} runs other software (rtcli {ours} here, {ours.split(' (')[0]} (sources "
                     "000000000000) there): its pixels could differ; install the same rtcli and libraries on every "
                     "worker (left out: the other workers take its tasks)"]


def test_a_worker_without_rtcli_is_named_and_left_out(cluster, joining, loaded):
    """Present when the render starts: named in a note. A task that reaches it anyway (Dask's
    scheduler knows nothing of rtcli's notes) ends that worker, which cannot read it, and runs again
    on the good one."""
    expected = render(loaded.scene, Job(24, 16))[0]
    good = next(iter(cluster.scheduler_info["workers"]))
    joining(cluster.scheduler_address, NO_RTCLI)
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        client.wait_for_workers(2, timeout=WAIT)
    notes = []
    with renders.Reach(Target(cluster.scheduler_address, timeout=10), notes.append) as reach:
        image, _ = renders.still(reach, loaded, Job(24, 16, tile=4))
    assert image.tobytes() == expected.tobytes()
    other = left_out_note(notes, good)
    assert notes[0] == (f"the worker {other} cannot run rtcli (ModuleNotFoundError: No module named 'rtcli.cluster'; "
                        "'rtcli' is not a package); install the same rtcli and libraries on every worker (left out: "
                        "the other workers take its tasks)")


def test_a_cluster_whose_only_worker_lacks_rtcli_is_refused_naming_it(joining, loaded):
    empty = distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                                     dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    try:
        joining(empty.scheduler_address, NO_RTCLI)
        with distributed.Client(empty.scheduler_address, set_as_default=False) as client:
            client.wait_for_workers(1, timeout=WAIT)
            worker = next(iter(client.scheduler_info()["workers"]))
        with pytest.raises(RtcliError) as e, renders.Reach(Target(empty.scheduler_address, timeout=10)) as reach:
            renders.still(reach, loaded, Job(24, 16))
        assert str(e.value) == (f"the worker {worker} cannot run rtcli (ModuleNotFoundError: No module named "
                                "'rtcli.cluster'; 'rtcli' is not a package); install the same rtcli and libraries "
                                "on every worker")
    finally:
        empty.close()
