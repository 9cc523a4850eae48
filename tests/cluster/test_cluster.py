"""Renders on a Dask cluster: byte for byte the local render, whatever the grouping or a killed worker.

One LocalCluster of two worker processes (one thread each) serves the module; its
scene uses an include, a mesh and a texture, so the workers build it from the bytes
the client read. The errors (no Dask, no scheduler, other software on a worker, a
lost cluster) are checked by their one line.

A worker that compiles the engine, and `rtcli warmup --cluster`, are checked on a
LocalCluster whose workers are threads of this process (`threads`), where the engine's
start-up is replaced by one that compiles for show: a real compile takes minutes. One
test compiles a small part of it for real, on a worker process with a cache of its own.
"""

from __future__ import annotations

import json
import logging
import os
import re
import signal
import sys
import threading
from collections import OrderedDict

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import same_image
from PIL import Image

from rtcli.api.loading import load_file
from rtcli.cli import main
from rtcli.cli import terminal as runs
from rtcli.cluster import renders, software, tasks
from rtcli.cluster import session as sessions
from rtcli.cluster.target import Target
from rtcli.compiled.loading import Load
from rtcli.errors import RtcliError
from rtcli.kernels import numba_cache, variants
from rtcli.rendering import frames
from rtcli.rendering.tiles import Job, render

pytestmark = pytest.mark.slow   # Dask schedulers and worker processes

distributed = pytest.importorskip("distributed")

SCENE = """\
include: [parts.yaml]
image: {width: 36, height: 24}
animation: {fps: 4, frames: 6}
camera:
  eye: [0, 1.5, 5]
  look_at: [0, 0.5, 0]
  transform: [{rotate: {axis: [0, 1, 0], degrees: {keys: {0: 0, 1.5: 120}}}}]
lights: [{position: [3, 5, 4], color: {keys: {0: [1, 1, 1], 1: [0.4, 0.6, 1]}}}]
objects:
  - {plane: {}, material: {texture: {image: grid.png}, reflection: 0.2}}
  - {mesh: {file: tri.obj}, material: shiny, transform: [{translate: {keys: {0: [0, 0, 0], 1.5: [0.5, 0.5, 0]}}}]}
  - {sphere: {center: [1, 0.5, 0], radius: 0.5}, material: {transmission: 0.8, ior: 1.5}}
"""
PARTS = "materials: {shiny: {diffuse: [0.8, 0.3, 0.2], specular: 0.5, reflection: 0.3}}\n"
MESH = "v -1 0 -1\nv 1 0 -1\nv 0 1.5 -1\nv 0 0 0\nf 1 2 3\nf 1 4 3\n"


@pytest.fixture(scope="module")
def cluster():
    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                 dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    yield c
    c.close()


@pytest.fixture(scope="module")
def threads():
    """Two workers in threads of this process (on loopback TCP, as a real cluster): what the tests
    replace in rtcli's modules, the workers run."""
    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp",
                                 host="127.0.0.1", dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    yield c
    c.close()


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.yaml").write_text(SCENE)
    (tmp_path / "parts.yaml").write_text(PARTS)
    (tmp_path / "tri.obj").write_text(MESH)
    picture = np.random.default_rng(1).integers(0, 255, (8, 8, 3), dtype=np.uint8)
    Image.fromarray(picture).save(tmp_path / "grid.png")
    runner = CliRunner()
    return lambda *args: runner.invoke(main, list(args))


def same_files(tmp_path, a: str, b: str) -> bool:
    """The same pixels and provenance, but the engine (the workers' may be another) and the time."""
    return same_image(tmp_path / a, tmp_path / b, ignore=("engine",))


@pytest.mark.parametrize("rays_per_task", [sessions.RAYS_PER_TASK, 50])
def test_a_still_on_the_cluster_is_the_local_render(run, tmp_path, cluster, monkeypatch, rays_per_task):
    """Tiles in groups (a few, or one tile a task) give the local render's bytes, on any frame."""
    monkeypatch.setattr(sessions, "RAYS_PER_TASK", rays_per_task)
    for frame in ("1", "4"):
        local = run("render", "scene.yaml", "--frame", frame, "--tile", "8", "-o", "local.png", "--stats")
        assert local.exit_code == 0, local.output
        result = run("render", "scene.yaml", "--frame", frame, "--tile", "8", "-o", "cluster.png",
                     "--cluster", cluster.scheduler_address, "--stats")
        assert result.exit_code == 0, result.output
        engine = next(part for part in local.output.split("; ") if part.endswith(" engine"))   # as chosen here
        assert "864 primary" in result.output and f"; {engine};" in result.output
        assert same_files(tmp_path, "local.png", "cluster.png"), frame


def test_a_signature_on_the_cluster_is_the_local_one(run, tmp_path, cluster):
    assert run("signature", "scene.yaml", "--ids", "local_ids.png", "-o", "local.png").exit_code == 0
    path = tmp_path / "scheduler.json"
    path.write_text(json.dumps({"address": cluster.scheduler_address}))
    result = run("signature", "scene.yaml", "--ids", "ids.png", "-o", "sig.png", "--cluster-file", str(path))
    assert result.exit_code == 0, result.output
    assert same_files(tmp_path, "local_ids.png", "ids.png") and same_files(tmp_path, "local.png", "sig.png")


def test_frames_on_the_cluster_are_the_local_frames(run, tmp_path, cluster):
    assert run("render", "scene.yaml", "-o", "local_%d.png", "--movie", "local.apng").exit_code == 0
    result = run("render", "scene.yaml", "-o", "c_%d.png", "--movie", "c.apng", "--cluster", cluster.scheduler_address)
    assert result.exit_code == 0, result.output
    for k in range(1, 7):
        assert same_files(tmp_path, f"local_{k}.png", f"c_{k}.png"), k
    assert same_files(tmp_path, "local.apng", "c.apng")


def test_a_killed_worker_costs_time_not_correctness(run, tmp_path, cluster):
    """A worker killed (SIGKILL) after the first frame: its frames run again elsewhere, same bytes."""
    assert run("render", "scene.yaml", "-o", "local_%d.png").exit_code == 0
    loaded = load_file("scene.yaml", keep=True)
    seq = frames.sequence(loaded.animation, "scene.yaml", "c_%d.png", None, None, None)
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        pids = client.run(os.getpid)
        killed = []

        def kill_one(done, total):
            if not killed:
                killed.append(pids[sorted(pids)[0]])
                os.kill(killed[0], signal.SIGKILL)
        job = Job(36, 24)
        with renders.Reach(Target(cluster.scheduler_address)) as reach:
            frames.render_sequence(loaded, seq, job, False, lambda todo: renders.frames(reach, loaded, todo, job, {},
                                                                                        kill_one))
        client.wait_for_workers(2, timeout=60)
        assert killed and killed[0] not in client.run(os.getpid).values()        # the nanny started another
    for k in range(1, 7):
        assert same_files(tmp_path, f"local_{k}.png", f"c_{k}.png"), k


def test_a_worker_with_other_software_is_refused(run, tmp_path, cluster, monkeypatch):
    ours = dict(software.fingerprint(), numpy="0.0")
    monkeypatch.setattr(software, "_fingerprint", ours)
    result = run("render", "scene.yaml", "-o", "c.png", "--cluster", cluster.scheduler_address)
    assert result.exit_code == 2
    line = result.output
    assert line.startswith("error: the worker tcp://127.0.0.1:") and line.count("\n") == 1
    assert line.endswith(f"runs other software (numpy 0.0 here, {np.__version__} there): its pixels could differ; "
                         "install the same rtcli and libraries on every worker\n")
    assert not (tmp_path / "c.png").exists()


def test_a_task_on_a_worker_refuses_a_client_with_other_software(cluster):
    spec = {"fingerprint": dict(software.fingerprint(), rtcli="0.0")}
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        future = client.submit(tasks.frame_task, spec, {}, 1, Job(4, 4), pure=False)
        with pytest.raises(RtcliError, match=r"runs other software \(rtcli 0.0 here, 0.1.0 \(sources"):
            future.result()


def test_the_local_cluster_option(run, tmp_path):
    assert run("render", "scene.yaml", "--frame", "2", "-o", "local.png").exit_code == 0
    result = run("render", "scene.yaml", "--frame", "2", "-o", "c.png", "--local-cluster", "2")
    assert result.exit_code == 0, result.output
    assert same_files(tmp_path, "local.png", "c.png")


def test_a_lost_cluster_keeps_the_frames_done_and_says_so(run, tmp_path):
    lost = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                    dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    loaded = load_file("scene.yaml", keep=True)
    seq = frames.sequence(loaded.animation, "scene.yaml", "c_%d.png", None, None, None)
    job = Job(36, 24)
    with pytest.raises(RtcliError) as e, renders.Reach(Target(lost.scheduler_address)) as reach:
        frames.render_sequence(loaded, seq, job, False,
                               lambda todo: renders.frames(reach, loaded, todo, job, {}, lambda done, total: lost.close()))
    assert str(e.value) == (f"lost the Dask scheduler at {lost.scheduler_address} mid-render "
                            "(FutureCancelledError); the render was stopped")
    written = sorted(p for p in os.listdir(tmp_path) if p.startswith("c_"))
    assert written and len(written) < 6 and not [p for p in os.listdir(tmp_path) if p.startswith(".rtcli-")]


@pytest.mark.parametrize("args, message", [
    (["--cluster", "tcp://127.0.0.1:1"], "cannot reach the Dask scheduler at tcp://127.0.0.1:1: Timed out trying "
                                         "to connect to tcp://127.0.0.1:1 after 0.5 s"),
    (["--cluster", "scheduler"], "--cluster scheduler: give the scheduler's address as tcp://HOST:PORT"),
    (["--cluster-file", "nowhere.json"], "--cluster-file nowhere.json: file not found"),
    (["--cluster-file", "scene.yaml"], "--cluster-file scene.yaml: not a Dask scheduler file (Expecting value: "
                                       "line 1 column 1 (char 0))"),
    (["--cluster", "tcp://127.0.0.1:1", "--local-cluster", "2"], "--cluster and --local-cluster: give one way "
                                                                 "to reach a cluster"),
])
def test_cluster_errors_are_one_line(run, tmp_path, args, message):
    import dask
    with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
        result = run("render", "scene.yaml", "-o", "c.png", *args)
    assert (result.exit_code, result.output) == (2, f"error: {message}\n")
    assert not (tmp_path / "c.png").exists()


def test_warmup_takes_the_cluster_options_as_render_does(run):
    import dask
    with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
        for args, message in [(["--cluster", "tcp://127.0.0.1:1"], "cannot reach the Dask scheduler at "
                                                                   "tcp://127.0.0.1:1: Timed out"),
                              (["--cluster-file", "nowhere.json"], "--cluster-file nowhere.json: file not found")]:
            result = run("warmup", *args)
            assert result.exit_code == 2 and result.output.startswith(f"error: {message}"), result.output
            assert result.output.count("\n") == 1


@pytest.mark.parametrize("command", [["render", "scene.yaml", "-o", "c.png"], ["signature", "scene.yaml", "-o", "c.png"],
                                     ["warmup"]])
def test_without_dask_the_error_names_the_extra(run, tmp_path, monkeypatch, command):
    monkeypatch.setitem(sys.modules, "distributed", None)                 # import distributed fails
    result = run(*command, "--local-cluster", "2")
    assert (result.exit_code, result.output) == (2, "error: a cluster needs Dask's distributed scheduler, which is "
                                                    "not installed: pip install -e '.[cluster]' in the rtcli folder "
                                                    "(rtcli is not on the package index)\n")
    assert not (tmp_path / "c.png").exists()


def test_groups_are_about_rays_per_task_and_several_per_worker():
    tiles = [(np.arange(16), np.arange(16))] * 100                      # 256 rays a tile
    assert sorted(len(g) for g in sessions.groups(tiles, 1, 2)) == [12] * 4 + [13] * 4
    assert sum(map(len, sessions.groups(tiles, 1, 2))) == 100
    big = [(np.arange(128), np.arange(128))] * 400                      # 6.5 million rays
    assert len(sessions.groups(big, 1, 1)) == 4 and len(sessions.groups(big, 2, 1)) == 14
    assert len(sessions.groups(tiles[:3], 1, 8)) == 3


def test_a_scene_builds_from_the_bytes_a_load_kept(run, tmp_path, monkeypatch):
    """The files a load read, served from memory elsewhere (another folder: nothing on disk), give
    the same scene; each content once in the bundle."""
    (tmp_path / "twice.yaml").write_text(SCENE.replace("parts.yaml]", "parts.yaml, copy.yaml]"))
    (tmp_path / "copy.yaml").write_text(PARTS)
    loaded = load_file("twice.yaml", frame=3, keep=True)
    bundle = renders.bundle(loaded)
    assert sorted(os.path.basename(m[0]) for m in bundle.manifest) == \
        ["copy.yaml", "grid.png", "parts.yaml", "tri.obj", "twice.yaml"]
    assert len(bundle.blobs) == 4 and bundle.size == sum(len(b) for b in bundle.blobs.values())
    monkeypatch.chdir(tmp_path.parent)
    spec = {"key": bundle.key, "scene_path": bundle.scene_path, "manifest": bundle.manifest, "overrides": {}}
    scene = tasks._scene(spec, bundle.blobs, 3)
    a, _ = render(scene, Job(36, 24))
    b, _ = render(loaded.scene, Job(36, 24))
    assert a.tobytes() == b.tobytes()


def test_workers_keep_the_scene_they_built_between_tasks(run, tmp_path, cluster, monkeypatch):
    """Many tasks of one still: each worker holds one parsed scene and one built frame for it."""
    monkeypatch.setattr(sessions, "RAYS_PER_TASK", 50)
    loaded = load_file("scene.yaml", frame=2, keep=True)
    with renders.Reach(Target(cluster.scheduler_address)) as reach:
        image, _ = renders.still(reach, loaded, Job(36, 24, tile=4))
    assert image.tobytes() == render(loaded.scene, Job(36, 24))[0].tobytes()
    key = renders.bundle(loaded).key

    def kept():
        return ([k for k in tasks._animations if k == key],
                [k[1] for k in tasks._scenes if k[0] == key])
    with distributed.Client(cluster.scheduler_address, set_as_default=False) as client:
        for animations, scenes in client.run(kept).values():
            assert (animations, scenes) in (([key], [2]), ([], []))      # a worker that got no task keeps none


def test_a_scheduler_without_workers_is_named(run, tmp_path):
    import dask
    empty = distributed.LocalCluster(n_workers=0, processes=False, dashboard_address="127.0.0.1:0",
                                     silence_logs=logging.CRITICAL)
    try:
        with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}):
            with pytest.raises(RtcliError) as e:
                with renders.Reach(Target(empty.scheduler_address)) as reach:
                    renders.still(reach, load_file("scene.yaml", keep=True), Job(36, 24))
        assert str(e.value) == (f"the Dask scheduler at {empty.scheduler_address} has no workers "
                                "(start some: README.md, Clusters)")
    finally:
        empty.close()


def test_several_scenes_on_the_cluster_are_the_local_renders_all_placed_or_none(run, tmp_path, cluster):
    """A folder's scenes share one connection; their images are staged and placed together."""
    (tmp_path / "more.yaml").write_text(SCENE.replace("eye: [0, 1.5, 5]", "eye: [1, 2, 5]"))
    for name in ("scene", "more"):
        assert run("render", f"{name}.yaml", "--frame", "3", "-o", f"{name}-local.png").exit_code == 0
    result = run("render", "scene.yaml", "more.yaml", "--frame", "3", "-o", "out", "--stats",
                 "--cluster", cluster.scheduler_address)
    assert result.exit_code == 0, result.output
    assert [line.split(": rays: ")[0] for line in result.output.splitlines()] == ["scene.yaml", "more.yaml"]
    for name in ("scene", "more"):
        assert same_files(tmp_path, f"{name}-local.png", f"out/{name}.png"), name
    (tmp_path / "bad.yaml").write_text(SCENE.replace("radius: 0.5", "radius: -1"))
    result = run("render", "scene.yaml", "bad.yaml", "-o", "none", "--cluster", cluster.scheduler_address)
    assert (result.exit_code, result.output) == (2, "error: bad.yaml:12:44: objects[2].sphere.radius: must be > 0, "
                                                    "got -1\n")
    assert not (tmp_path / "none").exists()


# --- the engine's start-up on the workers ---
COMPILING = "compiling the render engine, once (about half a minute); cached in /somewhere"


@pytest.fixture
def compiling(monkeypatch):
    """The engine's start-up on the `threads` workers (whose tasks give notes) replaced by one that says it compiles, waits
    until `heard` is set (at most 60 s; whether it was, in `waited`), and reports 2.5 s of compiling."""
    rendering = sys.modules["rtcli.rendering.engine"]
    real, heard, waited = rendering.prepare, threading.Event(), []

    def prepare(scene, job, traced, notes=None):
        if notes is None:                                # a render here, not on a worker
            return real(scene, job, traced)
        notes(COMPILING)
        waited.append(heard.wait(60))
        engine, load = real(scene, job, traced, notes)
        return engine, (load or Load()) + Load(2.5, 2.5)
    monkeypatch.setattr(rendering, "prepare", prepare)
    monkeypatch.setattr(tasks, "_scenes", OrderedDict())       # no scene kept from another test
    return heard, waited


def test_the_client_hears_a_worker_compile_while_the_render_runs(run, threads, compiling):
    """The note reaches the client while the worker still compiles (its task waits for it); after
    the render, a note for the worker that compiled, with its time. (The `threads` workers share
    this process's kept scenes: the first to prepare the engine prepares it for both.)"""
    heard, waited = compiling
    notes = []

    def note(text):
        notes.append(text)
        if text.endswith(COMPILING):
            heard.set()
    loaded = load_file("scene.yaml", frame=2, keep=True)
    with renders.Reach(Target(threads.scheduler_address), note) as reach:
        image, _ = renders.still(reach, loaded, Job(36, 24, tile=8))
    assert image.tobytes() == render(loaded.scene, Job(36, 24))[0].tobytes()
    assert waited == [True]                             # heard while the worker was still compiling
    worker = notes[0].split()[1].rstrip(":")
    assert worker in threads.scheduler_info["workers"]
    assert notes == [f"worker {worker}: {COMPILING}",
                     f"worker {worker} compiled the engine in 2.5 s (cached there for later renders)"]


def test_render_prints_the_workers_notes_before_the_bar_ends(run, threads, compiling):
    heard, _ = compiling
    heard.set()                                          # the worker need not wait: the order is checked
    result = run("render", "scene.yaml", "--frame", "3", "--tile", "8", "-o", "c.png", "--progress",
                 "--cluster", threads.scheduler_address)
    assert result.exit_code == 0, result.output
    err = result.stderr
    first = err.index(f": {COMPILING}\n")
    assert err[:first].startswith("note: worker tcp://127.0.0.1:") and "\n" not in err[:first]
    assert first < err.index("100%")
    assert err.rstrip("\n").splitlines()[-1].endswith(" compiled the engine in 2.5 s (cached there for later renders)")


def test_frames_on_a_cluster_tell_it_too(run, threads, compiling):
    """A frame a task: each frame's engine start-up (here, each compiles for show) is told, and the
    summary adds up each worker's seconds."""
    heard, _ = compiling
    heard.set()
    result = run("render", "scene.yaml", "--frames", "1-2", "-o", "f_%d.png", "--cluster", threads.scheduler_address)
    assert result.exit_code == 0, result.output
    lines = result.stderr.splitlines()
    assert [line.endswith(f": {COMPILING}") for line in lines[:2]] == [True, True]        # a note each frame
    summary = [re.fullmatch(r"note: worker tcp://127\.0\.0\.1:\d+ compiled the engine in ([\d.]+) s "
                            r"\(cached there for later renders\)", line) for line in lines[2:]]
    assert summary and all(summary) and sum(float(m[1]) for m in summary) == 5.0


def test_a_note_ends_the_progress_bar_line_it_comes_under(capsys):
    show = runs.progress_bar(True, "s")
    show(1, 2)
    runs.note("a worker speaks")
    show(2, 2)
    runs.note("done")
    bar = "\rs [" + "#" * 15 + " " * 15 + "]  50%"
    assert capsys.readouterr().err == (f"{bar}\nnote: a worker speaks\n\rs [{'#' * 30}] 100%\nnote: done\n")


def fake_warmup(compiles: set, fails: set):
    """rtcli.rendering.warmup.warmup for the `threads` workers: a worker whose address is in `compiles`
    compiles the render engine for show (3.5 s, with its note); one in `fails` cannot load numba."""
    def warmup(notes=None):
        address = notes.worker.address
        if address in fails:
            raise RtcliError("numba cannot be loaded (no module named numba)")
        if address in compiles:
            notes(COMPILING)
            notes("compiled in 3.5 s")
        seconds = 3.5 if address in compiles else 0.0
        return [("the render engine (compiled)", Load(seconds + 0.25, seconds)),
                ("the numpy engine's BVH walks", Load(0.25))], (["trace_camera", "levels"], None)
    return warmup


def test_warmup_on_a_cluster_reports_each_worker(run, threads, monkeypatch):
    from rtcli.rendering import warmup
    first, second = sorted(threads.scheduler_info["workers"])
    monkeypatch.setattr(warmup, "warmup", fake_warmup({second}, set()))
    result = run("warmup", "--cluster", threads.scheduler_address)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].startswith(f"{first}: already warm (loaded in ") and lines[0].endswith(" s)")
    assert lines[1].startswith(f"{second}: compiled in 3.5 s (the render engine (compiled) 3.5 s), ready in ")
    assert lines[2:] == ["2 workers warm, 1 of them compiled"]
    assert result.stderr == f"note: worker {second}: {COMPILING}\nnote: worker {second}: compiled in 3.5 s\n"


def test_a_worker_that_cannot_be_warmed_is_one_line_and_exit_2(run, threads, monkeypatch):
    from rtcli.rendering import warmup
    first, second = sorted(threads.scheduler_info["workers"])
    monkeypatch.setattr(warmup, "warmup", fake_warmup(set(), {first}))
    result = run("warmup", "--cluster", threads.scheduler_address)
    assert result.exit_code == 2
    assert result.stdout.startswith(f"{second}: already warm") and result.stdout.count("\n") == 1
    assert result.stderr == (f"error: 1 of 2 workers could not be warmed: {first}: numba cannot be loaded "
                             "(no module named numba)\n")


@pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")
def test_warmup_on_local_worker_processes_reports_each(run):
    """The real warmup on two worker processes sharing this machine's cache: each reports (already
    warm when `make warmup` ran, else compiled)."""
    result = run("warmup", "--local-cluster", "2")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert len(lines) == 3 and lines[2].startswith("2 workers warm, ")
    for line in lines[:2]:
        assert line.startswith("tcp://127.0.0.1:") and (": already warm (loaded in " in line or ": compiled in " in line)


def test_warmup_refuses_a_worker_with_other_software(run, cluster, monkeypatch):
    monkeypatch.setattr(software, "_fingerprint", dict(software.fingerprint(), numpy="0.0"))
    result = run("warmup", "--cluster", cluster.scheduler_address)
    assert result.exit_code == 2 and result.output.count("\n") == 1
    assert result.output.startswith("error: the worker tcp://127.0.0.1:")
    assert f"runs other software (numpy 0.0 here, {np.__version__} there)" in result.output


@pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")
def test_a_cold_worker_process_compiles_and_says_so(run, tmp_path):
    """A worker process with a cache of its own that lacks the BVH walks (they compile in seconds
    when what they call is cached; the integrator takes minutes): warmup compiles them there, for
    real, and the client hears it."""
    from helpers import WALKS, seeded

    from rtcli.rendering.warmup import warmup
    if numba_cache.cache_location().root is not None:
        pytest.skip("the cache is not beside the sources here (RTCLI_CACHE_DIR or NUMBA_CACHE_DIR is set)")
    warmup(notes=lambda text: None)                     # the cache to seed from, warm
    seeded_cache = seeded(tmp_path / "cache", WALKS)
    env = {numba_cache.CACHE_ENV: str(seeded_cache), "RTCLI_MACHINE_CODE": "0"}
    cold = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                                    dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL, env=env)
    try:
        result = run("warmup", "--cluster", cold.scheduler_address)
        again = run("warmup", "--cluster", cold.scheduler_address)
    finally:
        cold.close()
    assert result.exit_code == 0, result.output
    worker = result.stdout.split(": ")[0]
    assert result.stderr.splitlines() == [
        f"note: worker {worker}: compiling the numpy engine's BVH walks, once (about half a minute); cached in {seeded_cache}",
        result.stderr.splitlines()[1]]
    assert result.stderr.splitlines()[1].startswith(f"note: worker {worker}: compiled in ")
    assert result.stdout.startswith(f"{worker}: compiled in ") and "the numpy engine's BVH walks" in result.stdout
    assert again.exit_code == 0 and again.stdout.startswith(f"{worker}: already warm") and again.stderr == ""
