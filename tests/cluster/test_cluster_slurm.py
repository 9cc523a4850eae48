"""docs/cluster-slurm.md's commands run as written on this machine, which has no SLURM: the batch
script under bash, as SLURM's batch step would run it, with an `srun` that runs its command once
here; dask-jobqueue's script with an `sbatch` that runs the job's script here, in a session of its
own, and an `scancel` that stops it. Addresses, network and sizes change as in
tests/cluster/test_cluster_docs.py (CHANGES).
"""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

import pytest
from test_cluster_docs import BOUND, block, changed, commands, here, kill_group, processes, rendered_as_here, run

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.slow   # Dask schedulers and worker processes, started as the page says

__all__ = ["here", "processes"]   # the fixtures, shared with tests/cluster/test_cluster_docs.py


SRUN = """#!/bin/sh
# srun here: the command once, on this machine (SLURM's options left out)
while [ "${1#-}" != "$1" ]; do shift; done
exec "$@"
"""
SBATCH = """#!/bin/sh
# sbatch here: the job's script run on this machine, in a session of its own; its id is its process's
job="$(mktemp "$FAKE_SLURM/job.XXXXXX")"
cp "$1" "$job"
setsid bash "$job" > "$job.out" 2>&1 < /dev/null &
echo "$!" >> "$FAKE_SLURM/jobs"
echo "Submitted batch job $!"
"""
SCANCEL = """#!/bin/sh
kill -TERM -- "-$1" 2>/dev/null || true
echo "$1" >> "$FAKE_SLURM/cancelled"
"""


def tool(folder: Path, name: str, text: str) -> None:
    path = folder / "bin" / name
    path.write_text(text)
    path.chmod(0o755)


def test_the_slurm_batch_script_runs_as_its_batch_step(here, processes):
    folder, env = here
    tool(folder, "srun", SRUN)
    script = folder / "render.sbatch"
    script.write_text(changed(block("cluster-slurm.md", "sh", "#SBATCH"), 0))
    env.update(SLURM_JOB_ID="4242")
    job = processes.start(f"bash {script} > job.out 2>&1", folder, env)
    assert job.wait(BOUND) == 0, (folder / "job.out").read_text()
    assert (folder / "scheduler-4242.json").exists()
    for k in (1, 2):
        rendered_as_here(folder, f"out/frame_{k:04d}.png", env, "scenes/orbit.yaml", "--frame", str(k), "--width", "32")


def test_the_dask_jobqueue_script_runs_with_sbatch_here(here, processes):
    pytest.importorskip("dask_jobqueue")
    folder, env = here
    for name, text in (("sbatch", SBATCH), ("scancel", SCANCEL)):
        tool(folder, name, text)
    env["FAKE_SLURM"] = str(folder)
    (folder / "slurm_cluster.py").write_text(changed(block("cluster-slurm.md", "python", "SLURMCluster("), 0))
    lines = commands(block("cluster-slurm.md", "sh", "slurm_cluster.py"), 0)
    assert lines[1] == "python slurm_cluster.py &"
    assert run(lines[0], folder, env).returncode == 0
    cluster = subprocess.Popen(["python", "slurm_cluster.py"], cwd=folder, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    try:
        done = run("\n".join(lines[2:]), folder, env)
        assert done.returncode == 0, done.stderr
    finally:
        cluster.send_signal(signal.SIGINT)                    # Ctrl-C: the cluster closes, its jobs cancelled
        cluster.wait(60)
        jobs = (folder / "jobs").read_text().split() if (folder / "jobs").exists() else []
        for pid in jobs:
            kill_group(int(pid))
    assert len(jobs) == 1 and (folder / "cancelled").read_text().split() == jobs
    for k in (1, 2):
        rendered_as_here(folder, f"out/frame_{k:04d}.png", env, "scenes/orbit.yaml", "--frame", str(k), "--width", "32")
