"""Whole-job times of rtcli on this machine's cores against a Dask cluster, and what a task costs.

Three setups render the same jobs, alternately, `--runs` times each, every run a whole
`rtcli render` process timed by wall clock: the local pool (`--workers N`), a
LocalCluster started by the command (`--local-cluster N`), and a command-line
scheduler with N workers on loopback, started once by this script (`dask scheduler`,
`dask worker --nworkers N --nthreads 1`). The jobs: a 1920x1080 still of the Whitted
scene and a 60-frame animation of scenes/orbit.yaml at 640x480 (30 fps, 2 s). Every
output is compared with the local one byte for byte. Then, on the command-line cluster:
what a task costs beyond its work (tile groups of one pixel, their scene kept by the
workers): one at a time, the round trip; many at once, the busy time each adds to a
worker; and the size of each scene of scenes/ as sent to the workers.

The command-line cluster is started once and stays up, so from its second run on it
is a warm cluster (numba loaded, the scene kept by its workers); a LocalCluster
starts and stops with each command, and its start-up is in its times.

    python bench/cluster.py [--runs 3] [--workers 2] [--jobs still,frames]
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RTCLI = [sys.executable, "-m", "rtcli", "render", "--quiet"]


def timed(cmd: list[str]) -> float:
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(cmd)}\n{done.stderr[-2000:]}")
    return time.perf_counter() - start


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_cluster(workers: int, folder: str) -> tuple[list, str]:
    """`dask scheduler` and `dask worker` as README.md (Clusters) starts them: everything on loopback."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    log = open(os.path.join(folder, "dask.log"), "w")
    scheduler = subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                  "--dashboard-address", "127.0.0.1:0"], stdout=log, stderr=log)
    pool = subprocess.Popen([dask, "worker", address, "--nworkers", str(workers), "--nthreads", "1",
                             "--host", "127.0.0.1", "--dashboard-address", "127.0.0.1:0"], stdout=log, stderr=log)
    from distributed import Client
    with Client(address, timeout=60) as client:
        client.wait_for_workers(workers, timeout=60)
    return [pool, scheduler], address


def jobs(folder: str) -> dict:
    orbit = open(os.path.join(ROOT, "scenes", "orbit.yaml")).read()
    twelve = "animation: {fps: 12, clock: [0, 2]}"
    if twelve not in orbit:
        sys.exit(f"scenes/orbit.yaml has no `{twelve}` to make 60 frames of")
    scene60 = os.path.join(folder, "orbit60.yaml")
    with open(scene60, "w") as f:
        f.write(orbit.replace(twelve, "animation: {fps: 30, clock: [0, 2]}"))
    return {
        "still": ("still 1920x1080", ["scenes/whitted.yaml", "--width", "1920", "--height", "1080"], "still.png"),
        "frames": ("60 frames 640x480", [scene60, "--width", "640", "--height", "480"], "frame_%02d.png"),
    }


def same_outputs(a: str, b: str) -> bool:
    names = sorted(os.listdir(a))
    return names == sorted(os.listdir(b)) and all(
        open(os.path.join(a, n), "rb").read() == open(os.path.join(b, n), "rb").read() for n in names)


def task_costs(address: str, workers: int, runs: int = 200) -> tuple[float, float, float]:
    """(work, round trip, busy time a task adds to a worker), in seconds, of tile groups of one
    pixel of the Whitted scene, whose built scene every worker keeps after its first task."""
    sys.path.insert(0, ROOT)
    from rtcli.api.loading import load_file
    from rtcli.cluster.renders import bundle
    from rtcli.cluster.session import Session
    from rtcli.cluster.target import Target
    from rtcli.cluster.tasks import tiles_task
    from rtcli.rendering.tiles import Job, plan, prepare, run_tiles
    loaded = load_file(os.path.join(ROOT, "scenes", "whitted.yaml"), keep=True)
    job = Job(1, 1)
    tiles, traced = plan(loaded.scene, job)
    engine, _ = prepare(loaded.scene, job, traced)
    here = []
    for _ in range(runs):
        start = time.perf_counter()
        run_tiles(loaded.scene, engine, job, tiles)
        here.append(time.perf_counter() - start)
    with Session(Target(address)) as session:
        client = session.client
        spec, blobs = session.send(bundle(loaded), {})

        def submit():
            return client.submit(tiles_task, spec, blobs, 1, job, traced, tiles, pure=False)
        client.gather([submit() for _ in range(8 * workers)])         # every worker has built the scene
        trips = []
        for _ in range(runs // 4):
            start = time.perf_counter()
            submit().result()
            trips.append(time.perf_counter() - start)
        start = time.perf_counter()
        client.gather([submit() for _ in range(runs)])
        busy = (time.perf_counter() - start) * workers / runs
    return statistics.median(here), statistics.median(trips), busy


def bundle_sizes() -> list[tuple[str, int, int]]:
    sys.path.insert(0, ROOT)
    from rtcli.api.loading import load_file
    from rtcli.cluster.renders import bundle
    out = []
    for name in sorted(os.listdir(os.path.join(ROOT, "scenes"))):
        if name.endswith(".yaml"):
            files = bundle(load_file(os.path.join(ROOT, "scenes", name), keep=True))
            out.append((name, len(files.manifest), files.size))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--jobs", default="still,frames", help="which jobs: still, frames (comma-separated)")
    args = ap.parse_args()
    folder = tempfile.mkdtemp(prefix="rtcli-cluster-bench-")
    processes, address = start_cluster(args.workers, folder)
    try:
        setups = {"local pool": ["--workers", str(args.workers)],
                  "LocalCluster": ["--local-cluster", str(args.workers)],
                  "dask scheduler": ["--cluster", address]}
        print(f"{'job':<20} {'setup':<16} {'median s':>9} {'/ local':>8}  runs (s, in order)", flush=True)
        every = jobs(folder)
        if not set(args.jobs.split(",")) <= set(every):
            ap.error(f"--jobs: some of {', '.join(every)}")
        for job, scene_args, output in (every[name] for name in args.jobs.split(",")):
            times = {s: [] for s in setups}
            for run in range(args.runs):
                order = list(setups) if run % 2 == 0 else list(reversed(setups))      # alternate, and who goes first
                for setup in order:
                    out = os.path.join(folder, setup.replace(" ", "_"))
                    os.makedirs(out, exist_ok=True)
                    for f in os.listdir(out):
                        os.unlink(os.path.join(out, f))
                    times[setup].append(timed(RTCLI + scene_args + setups[setup] + ["-o", os.path.join(out, output)]))
            local = os.path.join(folder, "local_pool")
            base = statistics.median(times["local pool"])
            for setup, ts in times.items():
                same = same_outputs(local, os.path.join(folder, setup.replace(" ", "_")))
                print(f"{job:<20} {setup:<16} {statistics.median(ts):9.2f} {statistics.median(ts) / base:8.2f}  "
                      f"{', '.join(f'{t:.2f}' for t in ts)}{'' if same else '  OUTPUT DIFFERS'}", flush=True)
        work, trip, busy = task_costs(address, args.workers)
        print(f"a one-pixel task on the command-line cluster ({args.workers} workers): work {1000 * work:.1f} ms "
              f"here; round trip {1000 * trip:.1f} ms one at a time; {1000 * busy:.1f} ms of a worker's time "
              f"each, {args.workers * 100} at once")
        for name, files, size in bundle_sizes():
            print(f"bundle {name:<22} {files:3d} files {size:>12,} bytes")
    finally:
        for p in processes:
            p.terminate()
            p.wait(timeout=30)


if __name__ == "__main__":
    main()
