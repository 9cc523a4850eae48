"""The cluster's edges (docs/cluster.md): an address where no Dask scheduler listens gives one line
within the connect deadline, and a worker that cannot run this rtcli, or runs other software, is
left out and named while the render goes on.

Every peer is on loopback: a socket server that accepts and says nothing, one that speaks HTTP,
one that answers in another protocol, one that closes at once, a LocalCluster's own dashboard
(the 8786/8787 typo) and one of its workers given for the scheduler. The commands run as
processes, each with a bound on its time (a hang fails the test instead of stopping the run).
The workers with other software are `dask worker` processes whose preload script changes what
this rtcli reports there.
"""

from __future__ import annotations

import contextlib
import http.server
import logging
import os
import socket
import subprocess
import sys
import threading
import time

import pytest
from helpers import CLUSTER_SCENE, same_image

from rtcli.cluster import probe as probes
from rtcli.cluster import renders
from rtcli.cluster.leftout import cannot_run, survey
from rtcli.cluster.target import Target
from rtcli.errors import RtcliError

distributed = pytest.importorskip("distributed")
slow = pytest.mark.slow          # an rtcli process each, or a Dask scheduler

SCENE = CLUSTER_SCENE
BOUND = 90                       # seconds any command here may take before the test fails
DEADLINE = 1.0                   # --cluster-timeout in these tests
ADVICE = "give the address `dask scheduler` prints (tcp://HOST:8786 by default; 8787 is its dashboard)"


def rtcli(*args, cwd) -> tuple[int, str, str, float]:
    """(exit code, stdout, stderr, seconds) of `rtcli ARGS` run as a process, within BOUND seconds."""
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "rtcli", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=BOUND, env={**os.environ, "RTCLI_NUMBA": "0"})
    return done.returncode, done.stdout, done.stderr, time.monotonic() - start


@pytest.fixture
def scene(tmp_path):
    (tmp_path / "scene.yaml").write_text(SCENE)
    return tmp_path


@contextlib.contextmanager
def server(answer):
    """A loopback TCP server whose every connection is given to `answer(conn)` in a thread; its port."""
    listener = socket.create_server(("127.0.0.1", 0))
    conns, stop = [], threading.Event()

    def serve():
        while not stop.is_set():
            with contextlib.suppress(OSError):
                conn, _ = listener.accept()
                conns.append(conn)
                threading.Thread(target=answer, args=(conn,), daemon=True).start()
    listener.settimeout(0.2)
    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield listener.getsockname()[1]
    finally:
        stop.set()
        thread.join(5)
        for conn in conns:
            conn.close()
        listener.close()


def silent(conn):
    """Accept and never speak (a port whose program reads and waits, as a dashboard given Dask's bytes)."""


def ssh_like(conn):
    conn.sendall(b"SSH-2.0-OpenSSH_9.2p1\r\n")


def closing(conn):
    conn.shutdown(socket.SHUT_RDWR)


class Quiet(http.server.BaseHTTPRequestHandler):
    def do_GET(self):
        self.send_response(404)
        self.end_headers()

    def log_message(self, *args):
        pass


@contextlib.contextmanager
def http_server():
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield httpd.server_address[1]
    finally:
        httpd.shutdown()
        httpd.server_close()


def refused_in_one_line(scene, port, what: str) -> float:
    """Render on 127.0.0.1:port: one `error:` line, `what` in it, exit 2, no image; its seconds."""
    code, out, err, seconds = rtcli("render", "scene.yaml", "-o", "c.png", "--cluster", f"127.0.0.1:{port}",
                                    "--cluster-timeout", str(DEADLINE), cwd=scene)
    assert (code, out) == (2, "")
    assert err == f"error: tcp://127.0.0.1:{port} is not a Dask scheduler: it {what}; {ADVICE}\n"
    assert not (scene / "c.png").exists()
    return seconds


@slow
def test_a_peer_that_accepts_and_never_speaks_is_one_line_within_the_deadline(scene):
    with server(silent) as port:
        refused_in_one_line(scene, port, f"accepted the connection but said nothing within {DEADLINE:g} s")


def test_a_silent_peer_costs_the_deadline_not_more():
    """The probe alone (no process start-up): a silent peer takes the deadline, give or take the
    threads' scheduling, never Dask's own 30 s or forever."""
    with server(silent) as port:
        start = time.monotonic()
        with pytest.raises(RtcliError, match="said nothing within 2 s"):
            probes.probe(f"tcp://127.0.0.1:{port}", 2.0, distributed)
        assert 1.9 <= time.monotonic() - start < 2.0 + 5


@pytest.mark.parametrize("peer, what", [
    ("http", "speaks HTTP (a web server, or a Dask dashboard)"),
    (ssh_like, "answered in another protocol than Dask's (its first bytes: b'SSH-2.0-OpenSSH_')"),
    (closing, "closed the connection without a word"),
])
def test_the_probe_tells_what_answers_instead_of_a_scheduler(peer, what):
    """In this process (the command's one line is checked by the slow tests): a peer silent for
    1.25 s (a quarter of the deadline) is asked in HTTP."""
    with http_server() if peer == "http" else server(peer) as port:
        with pytest.raises(RtcliError) as e:
            probes.probe(f"tcp://127.0.0.1:{port}", 5.0, distributed)
    assert str(e.value) == f"tcp://127.0.0.1:{port} is not a Dask scheduler: it {what}; {ADVICE}"


@slow
def test_a_server_that_speaks_http_is_one_line(scene):
    with http_server() as port:
        refused_in_one_line(scene, port, "speaks HTTP (a web server, or a Dask dashboard)")


@slow
def test_the_schedulers_own_dashboard_port_is_one_line(scene):
    """The 8786/8787 typo: the port of a real scheduler's HTTP server (its dashboard) instead of its own."""
    cluster = distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                                       dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    try:
        port = cluster.scheduler.http_server.port
        refused_in_one_line(scene, port, "speaks HTTP (a web server, or a Dask dashboard)")
    finally:
        cluster.close()


@slow
@pytest.mark.parametrize("answer, what", [
    (ssh_like, "answered in another protocol than Dask's (its first bytes: b'SSH-2.0-OpenSSH_')"),
    (closing, "closed the connection without a word"),
])
def test_a_peer_that_answers_otherwise_is_one_line(scene, answer, what):
    with server(answer) as port:
        refused_in_one_line(scene, port, what)


@slow
@pytest.mark.parametrize("port", ["0", "99999", "123456"])
def test_a_port_that_cannot_exist_is_one_line_at_once(scene, port):
    code, out, err, _ = rtcli("render", "scene.yaml", "-o", "c.png", "--cluster", f"127.0.0.1:{port}", cwd=scene)
    if len(port) > 5:
        assert err == f"error: --cluster 127.0.0.1:{port}: give the scheduler's address as tcp://HOST:PORT\n"
    else:
        assert err == (f"error: --cluster 127.0.0.1:{port}: no port can be {port}: give the scheduler's port, "
                       "1 to 65535 (8786 by default)\n")
    assert (code, out) == (2, "") and not (scene / "c.png").exists()


@slow
def test_a_refused_port_gives_up_at_the_deadline(scene):
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
    code, _, err, _ = rtcli("warmup", "--cluster", f"127.0.0.1:{port}", "--cluster-timeout", "0.5", cwd=scene)
    assert (code, err) == (2, f"error: cannot reach the Dask scheduler at tcp://127.0.0.1:{port}: Timed out trying "
                              f"to connect to tcp://127.0.0.1:{port} after 0.5 s\n")


@slow
def test_a_worker_given_for_the_scheduler_is_named(scene):
    cluster = distributed.LocalCluster(n_workers=1, processes=False, protocol="tcp", host="127.0.0.1",
                                       dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    try:
        worker = next(iter(cluster.scheduler_info["workers"]))
        code, out, err, _ = rtcli("render", "scene.yaml", "-o", "c.png", "--cluster", worker,
                                  "--cluster-timeout", "5", cwd=scene)
        assert (code, out) == (2, "")
        assert err == (f"error: {worker} is a Dask worker, not the scheduler: give the address `dask scheduler` "
                       "prints (tcp://HOST:8786 by default)\n")
    finally:
        cluster.close()


def test_the_deadline_is_the_option_else_20_s_or_dasks_when_shorter():
    import dask
    assert probes.deadline(3.5) == 3.5
    with dask.config.set({"distributed.comm.timeouts.connect": "30s"}):
        assert probes.deadline(None) == 20.0
    with dask.config.set({"distributed.comm.timeouts.connect": "4s"}):
        assert probes.deadline(None) == 4.0 and probes.deadline(9) == 9


@slow
@pytest.mark.parametrize("command", ["render", "signature", "warmup"])
def test_every_cluster_command_takes_the_timeout_option(scene, command):
    code, out, _, _ = rtcli(command, "--help", cwd=scene)
    assert code == 0 and "--cluster-timeout SECONDS" in out
    args = ["scene.yaml", "-o", "c.png"] if command != "warmup" else []
    code, _, err, _ = rtcli(command, *args, "--cluster", "127.0.0.1:8786", "--cluster-timeout", "0", cwd=scene)
    assert code == 2 and "--cluster-timeout" in err and "0.1" in err


def test_cannot_run_rtcli_names_the_worker():
    class Client:
        def run(self, function, on_error):
            return {"tcp://10.0.0.7:4000": ModuleNotFoundError("No module named 'rtcli'"),
                    "tcp://10.0.0.8:4000": function(), "tcp://10.0.0.9:4000": OSError("gone")}
    found = survey(Client())
    assert found == {"tcp://10.0.0.7:4000": found["tcp://10.0.0.7:4000"], "tcp://10.0.0.8:4000": None}
    assert str(found["tcp://10.0.0.7:4000"]) == str(cannot_run("tcp://10.0.0.7:4000", ModuleNotFoundError(
        "No module named 'rtcli'"))) == ("the worker tcp://10.0.0.7:4000 cannot run rtcli (ModuleNotFoundError: "
                                         "No module named 'rtcli'); install the same rtcli and libraries on every "
                                         "worker")


@slow
def test_a_still_on_a_tcp_cluster_through_the_probe_is_the_local_render(scene):
    """A real scheduler passes the probe (and the client it is followed by), in a fresh process with
    the default deadline."""
    cluster = distributed.LocalCluster(n_workers=1, processes=False, protocol="tcp", host="127.0.0.1",
                                       dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL)
    try:
        assert rtcli("render", "scene.yaml", "-o", "local.png", cwd=scene)[0] == 0
        code, _, err, _ = rtcli("render", "scene.yaml", "-o", "c.png", "--cluster", cluster.scheduler_address,
                                cwd=scene)                         # the default deadline (Dask's config read)
        assert code == 0, err
        assert same_image(scene / "c.png", scene / "local.png", ignore=("engine",))
    finally:
        cluster.close()


def test_renders_reach_takes_the_timeout_to_the_session():
    with renders.Reach(Target("tcp://127.0.0.1:1", timeout=0.3)) as reach:
        with pytest.raises(RtcliError, match=r"after 0.3 s$"):
            reach.session()


@slow
@pytest.mark.parametrize("command", [["render", "scene.yaml", "-o", "c.png"], ["warmup"]])
def test_the_timeout_without_a_cluster_is_refused(scene, command):
    code, out, err, _ = rtcli(*command, "--cluster-timeout", "3", cwd=scene)
    assert (code, out, err) == (2, "", "error: --cluster-timeout goes with --cluster, --cluster-file or "
                                       "--local-cluster\n")
    assert not (scene / "c.png").exists()
