"""The cluster pages' commands (docs/cluster.md, docs/cluster-slurm.md, docs/cluster-kubernetes.md)
run as written, on loopback, with only addresses and sizes changed (CHANGES).

- The set-up of several machines and its TLS variant: `dask scheduler`, `dask worker` and
  `rtcli render` as processes on 127.0.0.1, with the certificates made by the page's openssl lines.
- SLURM's page: tests/cluster/test_cluster_slurm.py; the SSHCluster script: tests/cluster/test_cluster_ssh.py.
- Every rtcli line of the three pages, Kubernetes' included (no cluster here), is accepted by
  rtcli's command line, its address as rtcli reads it.

`rtcli warmup` lines compile the engine on the workers (minutes when cold): tests/cluster/test_cluster.py
warms clusters it starts. Every process started here is stopped at the end of its test.
"""

from __future__ import annotations

import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import CLUSTER_SCENE, same_image

from rtcli.cli import main
from rtcli.cluster.target import target

distributed = pytest.importorskip("distributed")
slow = pytest.mark.slow          # Dask schedulers and worker processes, started as the page says

ROOT = Path(__file__).resolve().parents[2]
PAGES = ["cluster.md", "cluster-slurm.md", "cluster-kubernetes.md"]
BOUND = 240                      # seconds a page's commands may take here
SCENE = CLUSTER_SCENE


def CHANGES(port: int) -> list[tuple[str, str]]:
    """What changes in the pages' commands here: the machines' addresses and network become
    loopback, the ports free ones, the sizes small."""
    return [("10.0.0.1", "127.0.0.1"), ("10.0.0.2", "127.0.0.1"), ("10.0.0.3", "127.0.0.1"), (":8786", f":{port}"),
            ("--port 8786", f"--port {port}"), ('"port": 8786', f'"port": {port}'), ("127.0.0.1:8787", "127.0.0.1:0"),
            ("--worker-port 9000:9099", "--worker-port 0"),
            ("--nanny-port 9100:9199", "--nanny-port 0"), ("--nworkers 8", "--nworkers 1"),
            ("--interface ib0", "--interface lo"), ('interface="ib0"', 'interface="lo"'),
            ("cores=8, processes=8", "cores=1, processes=1"), ("jobs=4", "jobs=1"),
            ("--frames 1-240", "--frames 1-2 --width 32")]


def blocks(page: str, kind: str) -> list[str]:
    """The page's fenced blocks of that kind, in order."""
    text = (ROOT / "docs" / page).read_text()
    return [body for k, body in re.findall(r"^```(\w+)\n(.*?)^```$", text, re.M | re.S) if k == kind]


def block(page: str, kind: str, containing: str) -> str:
    found = [b for b in blocks(page, kind) if containing in b]
    assert len(found) == 1, (page, containing)
    return found[0]


def changed(text: str, port: int) -> str:
    for old, new in CHANGES(port):
        text = text.replace(old, new)
    return text


def commands(text: str, port: int) -> list[str]:
    """The block's command lines, changed for here (comments left out)."""
    return [line for line in changed(text, port).splitlines() if line.strip() and not line.startswith("#")]


def free_port() -> int:
    with socket.create_server(("127.0.0.1", 0)) as s:
        return s.getsockname()[1]


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A folder with the test's scene, `scenes` (rtcli's), a home whose ~/rtcli is rtcli's folder,
    and an environment for the commands: that home, rtcli's venv first on PATH, the numpy engine
    (nothing to compile)."""
    (tmp_path / "scene.yaml").write_text(SCENE)
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "rtcli").symlink_to(ROOT)
    bin_ = tmp_path / "bin"
    bin_.mkdir()
    env = {**os.environ, "HOME": str(tmp_path / "home"), "RTCLI_NUMBA": "0",
           "PATH": f"{bin_}:{Path(sys.executable).parent}:{os.environ['PATH']}"}
    return tmp_path, env


class Processes:
    """Background processes of a test, each in a session of its own, stopped (their whole group)
    at the end."""

    def __init__(self):
        self.started = []

    def start(self, line: str, cwd, env) -> subprocess.Popen:
        process = subprocess.Popen(line, shell=True, cwd=cwd, env=env, start_new_session=True,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.started.append(process)
        return process

    def stop(self):
        for process in reversed(self.started):
            kill_group(process.pid, process)


def kill_group(pid: int, leader: subprocess.Popen | None = None) -> None:
    """SIGTERM to the process group, then SIGKILL to what is left of it after 10 s. `leader`, the
    group's first process when it is this process's child, is reaped as it ends (a zombie would
    keep the group alive to the end of the wait)."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(pid, sig)
        except ProcessLookupError:
            return
        end = time.monotonic() + 10
        while time.monotonic() < end:
            if leader is not None:
                leader.poll()
            try:
                os.killpg(pid, 0)
            except ProcessLookupError:
                return
            time.sleep(0.1)


@pytest.fixture
def processes():
    p = Processes()
    yield p
    p.stop()


def run(line: str, cwd, env) -> subprocess.CompletedProcess:
    return subprocess.run(line, shell=True, cwd=cwd, env=env, capture_output=True, text=True, timeout=BOUND)


def rendered_as_here(folder: Path, name: str, env, *args) -> None:
    """`name` is byte for byte the local render of the scene it came from (rtcli render ARGS)."""
    assert run(shlex.join(["rtcli", "render", *args, "-o", "local.png"]), folder, env).returncode == 0
    assert same_image(folder / name, folder / "local.png", ignore=("engine",)), name


def wait_for_worker(address: str) -> None:
    with distributed.Client(address, set_as_default=False, timeout=60) as client:
        client.wait_for_workers(1, timeout=60)


def wait_listening(port: int) -> None:
    """Until something accepts connections at 127.0.0.1:port (at most 60 s)."""
    end = time.monotonic() + 60
    while time.monotonic() < end:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return
        except OSError:
            time.sleep(0.2)


# --- docs/cluster.md ---
@slow
def test_the_set_up_of_several_machines_runs_on_loopback(here, processes):
    folder, env = here
    port = free_port()
    lines = [line for line in commands(block("cluster.md", "sh", "dask scheduler --host"), port)
             if not line.startswith("rtcli warmup")]
    assert [line.split()[:2] for line in lines] == [["dask", "scheduler"], ["dask", "worker"], ["rtcli", "render"]]
    processes.start(lines[0], folder, env)
    processes.start(lines[1], folder, env)
    wait_for_worker(f"tcp://127.0.0.1:{port}")
    done = run(lines[2], folder, env)
    assert done.returncode == 0, done.stderr
    rendered_as_here(folder, "scene.png", env, "scene.yaml")


@slow
@pytest.mark.skipif(not os.path.exists("/usr/bin/openssl"), reason="no openssl to make the certificates")
def test_the_tls_set_up_runs_on_loopback(here, processes):
    folder, env = here
    port = free_port()
    for line in commands(block("cluster.md", "sh", "openssl req -x509"), port):
        assert run(line, folder, env).returncode == 0, line
    lines = commands(block("cluster.md", "sh", "--protocol tls"), port)
    for line in [line for line in lines if line.startswith("export ")]:
        name, value = line.split()[1].split("=", 1)
        env[name] = value
    scheduler, worker, render = [line for line in lines if not line.startswith("export ")]
    assert "tls://" in worker and "tls://" in render
    processes.start(scheduler, folder, env)
    processes.start(worker, folder, env)
    wait_listening(port)
    plain = run(render.replace("tls://", "tcp://") + " --cluster-timeout 5", folder, env)
    assert plain.returncode == 2 and plain.stderr == (f"error: tcp://127.0.0.1:{port} speaks TLS: give it as "
                                                      f"tls://127.0.0.1:{port}, with Dask's TLS settings "
                                                      "(docs/cluster.md, TLS)\n")
    done = run(render + " --cluster-timeout 60", folder, env)
    assert done.returncode == 0, done.stderr
    rendered_as_here(folder, "scene.png", env, "scene.yaml")


@slow
def test_the_fingerprint_line_prints_what_rtcli_compares(here):
    folder, env = here
    line = block("cluster.md", "sh", "fingerprint()").strip()
    done = run(line, folder, env)
    assert done.returncode == 0, done.stderr
    found = eval(done.stdout, {})                        # the dict's repr, as the page shows it printed
    assert set(found) == {"rtcli", "python", "numpy", "numba", "llvmlite", "PIL", "yaml"}
    assert found["rtcli"].startswith("0.1.0 (sources ") and found["numpy"] == __import__("numpy").__version__


# --- every page's rtcli lines ---
RTCLI = re.compile(r"\brtcli (render|signature|warmup) .*")


def rtcli_lines() -> list[tuple[str, str]]:
    found = []
    for page in PAGES:
        for body in blocks(page, "sh"):
            for line in body.splitlines():
                if not line.lstrip().startswith("#") and (command := RTCLI.search(line)):
                    found.append((page, command[0]))
    return found


def test_the_pages_show_rtcli_lines_of_each_kind():
    lines = [line for _, line in rtcli_lines()]
    assert len(lines) >= 7
    assert any("--cluster tls://" in line for line in lines) and any("--cluster-file" in line for line in lines)
    assert any("--cluster tcp://rtcli-dask-scheduler:8786" in line for line in lines)


@pytest.mark.parametrize("page, line", rtcli_lines())
def test_every_rtcli_line_of_the_pages_is_accepted(page, line):
    """The command line parses (every option known, every value valid) and its address is one
    rtcli takes; a line for a scheduler file names it."""
    args = shlex.split(line.replace('"$scheduler"', "scheduler.json"))[1:]
    command = main.get_command(None, args[0])
    context = command.make_context(args[0], args[1:])
    params = context.params
    assert params.get("cluster") or params.get("cluster_file"), line
    if params.get("cluster"):
        where = target(params["cluster"], None, None, params.get("cluster_timeout"))
        assert re.fullmatch(r"(tcp|tls)://[\w.-]+:\d+", where.address) and where.timeout == params["cluster_timeout"]
