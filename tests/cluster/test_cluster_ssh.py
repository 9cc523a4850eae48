"""docs/cluster.md's SSHCluster script runs as written, against an SSH server on loopback.

This machine has no sshd, and one could not run here without root's set-up; so the server is
asyncssh's own, in a thread of the test: it logs in the test's key only and runs each command
with /bin/sh, as sshd does. Dask's SSHCluster is the real client: it logs in, starts the
scheduler and the workers with their command lines, and stops them on Ctrl-C. The machines'
addresses, the network and the sizes change as in tests/cluster/test_cluster_docs.py; the login (port,
key, no known_hosts) is the test server's; remote_python is this Python.
"""

from __future__ import annotations

import asyncio
import contextlib
import signal
import subprocess
import sys
import threading

import pytest
from test_cluster_docs import BOUND, block, changed, commands, free_port, here, kill_group, rendered_as_here, run

asyncssh = pytest.importorskip("asyncssh")
distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.slow   # an SSH server, a Dask scheduler and worker processes

__all__ = ["here"]                # the fixture, shared with tests/cluster/test_cluster_docs.py


class Server(asyncssh.SSHServer):
    """Logs in the test's key, for any user; stops what a connection started when it closes."""

    def __init__(self, children: list):
        self.children = children

    def begin_auth(self, username: str) -> bool:
        return True

    def connection_lost(self, exc) -> None:
        for child in self.children:
            kill_group(child.pid, child)


class SSH:
    """asyncssh's SSH server on 127.0.0.1 (`port`), in a thread with its own event loop, running
    each command with /bin/sh in the environment `env`, in a session of its own."""

    def __init__(self, client_key, env: dict):
        self.env, self.children, self.port = env, [], None
        self.loop, ready = asyncio.new_event_loop(), threading.Event()
        self.thread = threading.Thread(target=self._serve, args=(client_key, ready), daemon=True)
        self.thread.start()
        assert ready.wait(30) and self.port

    def _serve(self, client_key, ready):
        asyncio.set_event_loop(self.loop)
        keys = asyncssh.import_authorized_keys(client_key.export_public_key().decode())
        server = self.loop.run_until_complete(asyncssh.create_server(
            lambda: Server(self.children), "127.0.0.1", 0, server_host_keys=[asyncssh.generate_private_key(
                "ssh-ed25519")], authorized_client_keys=keys, process_factory=self._run))
        self.port = server.sockets[0].getsockname()[1]
        ready.set()
        self.loop.run_forever()
        server.close()
        self.loop.run_until_complete(server.wait_closed())

    async def _run(self, process):
        child = subprocess.Popen(process.command, shell=True, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, start_new_session=True, env=self.env)
        self.children.append(child)
        await process.redirect(stdout=child.stdout, stderr=child.stderr)
        process.exit(await asyncio.get_running_loop().run_in_executor(None, child.wait))

    def stop(self):
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(30)
        for child in self.children:
            kill_group(child.pid, child)


def test_the_ssh_cluster_script_runs_against_an_ssh_server_here(here, tmp_path):
    folder, env = here
    key = asyncssh.generate_private_key("ssh-ed25519")
    key.write_private_key(str(tmp_path / "id_ed25519"))
    ssh = SSH(key, env)
    port = free_port()
    login = f'{{"known_hosts": None, "port": {ssh.port}, "client_keys": ["{tmp_path / "id_ed25519"}"]}}'
    script = changed(block("cluster.md", "python", "SSHCluster("), port)
    for old, new in [('{"known_hosts": "~/.ssh/known_hosts"}', login), ('"eth0"', '"lo"'),
                     ('"n_workers": 8', '"n_workers": 1'), ('"/opt/rtcli/.venv/bin/python"', repr(sys.executable))]:
        assert old in script
        script = script.replace(old, new)
    (folder / "ssh_cluster.py").write_text(script)
    lines = commands(block("cluster.md", "sh", "ssh_cluster.py"), port)
    assert lines[1] == "python ssh_cluster.py &"
    try:
        assert run(lines[0], folder, env).returncode == 0
        cluster = subprocess.Popen(["python", "ssh_cluster.py"], cwd=folder, env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        try:
            done = run("\n".join(lines[2:]), folder, env)
            assert done.returncode == 0, done.stderr
            with distributed.Client(f"tcp://127.0.0.1:{port}", set_as_default=False, timeout=30) as client:
                assert len(client.nthreads()) == 2             # a worker on each of the two workers' "machines"
        finally:
            cluster.send_signal(signal.SIGINT)                 # Ctrl-C: the scheduler and the workers stop
            assert cluster.wait(BOUND) == 0
        started = [child.args for child in ssh.children if "distributed.cli.dask_spec" in child.args]
        assert len(started) == 3                               # the scheduler and two workers, over SSH
        assert all(stopped(child) for child in ssh.children)
    finally:
        ssh.stop()
    rendered_as_here(folder, "scene.png", env, "scene.yaml")


def stopped(child: subprocess.Popen) -> bool:
    """Whether the command ended within 30 s."""
    with contextlib.suppress(subprocess.TimeoutExpired):
        child.wait(30)
    return child.poll() is not None
