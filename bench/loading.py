"""Scene loading: where the time goes, and whole commands against another checkout of rtcli.

Phases (in this process, CPU seconds, the least of --repeat runs): the YAML tree and the
scene built from it for spheres1k; the OBJ file read, the Mesh built and its BVH (numpy's
build and the compiled one) for torus100k.

With --old DIR (another checkout, say `git worktree add /tmp/old main`), each command runs
as a whole process, this checkout's and DIR's alternately, --runs times each, and the table
gives the medians of their wall-clock seconds and new / old. Both run on this Python
(sys.executable), each with its own folder first on PYTHONPATH; run each command once
before (--warm, the default) so that byte code and numba's cache are written.

    python bench/loading.py [--repeat 5] [--old DIR --runs 7 --commands validate,render]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
COMMANDS = {
    "import": ["-c", "import rtcli.cli, rtcli.scenefile.build"],
    "validate": ["-m", "rtcli", "validate", "{scene}.yaml"],
    "render": ["-m", "rtcli", "render", "{scene}.yaml", "-o", "{out}", "--width", "1920", "--height", "1080",
               "--workers", "2", "--quiet"],
}


def cpu(f, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        f()
        best = min(best, time.process_time() - start)
    return best


def phases(repeat: int) -> None:
    sys.path.insert(0, ROOT)
    import numpy as np

    from rtcli.kernels import variants
    from rtcli.compiled import build as compiled_build
    from rtcli.core import bvh_build
    from rtcli.scenefile import load, yamlfile
    from rtcli.scenefile.obj import read_obj
    from rtcli.shapes.mesh import Mesh

    spheres, torus = os.path.join(HERE, "spheres1k.yaml"), os.path.join(HERE, "torus100k.obj")
    docs = lambda: yamlfile.load(spheres)                                      # noqa: E731
    rows = [("spheres1k: YAML tree", cpu(docs, repeat)),
            ("spheres1k: scene from the tree", cpu(lambda: load.scene_from_docs(docs()), repeat) - cpu(docs, repeat)),
            ("spheres1k: load_scene", cpu(lambda: load.load_scene(spheres), repeat))]
    obj = read_obj(torus)
    mesh = Mesh.from_values(obj)
    lo, hi = mesh._boxes
    rows += [("torus100k: OBJ read", cpu(lambda: read_obj(torus), repeat)),
             ("torus100k: Mesh (no tree)", cpu(lambda: Mesh.from_values(obj), repeat)),
             ("torus100k: BVH, numpy build", cpu(lambda: bvh_build.numpy_build(lo, hi, 4, 12), repeat))]
    if variants.ENABLED:
        compiled_build.build(lo[:8], hi[:8], 4, 12)                        # numba loads, or compiles once
        rows.append(("torus100k: BVH, compiled build", cpu(lambda: compiled_build.build(lo, hi, 4, 12), repeat)))
    print(f"{'phase (CPU s, least of ' + str(repeat) + ')':<40} {'s':>7}")
    for name, seconds in rows:
        print(f"{name:<40} {seconds:7.3f}")
    del np


def whole(command: str, scene: str, tree: str, out: str) -> float:
    args = [a.format(scene=os.path.join(HERE, scene), out=out) for a in COMMANDS[command]]
    env = dict(os.environ, PYTHONPATH=tree)
    env.pop("PYTHONDONTWRITEBYTECODE", None)               # as installed: byte code written once, then read
    start = time.perf_counter()
    done = subprocess.run([sys.executable, *args], cwd=tree, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"failed in {tree}: {' '.join(args)}\n{done.stderr[-2000:]}")
    return seconds


def compare(old: str, runs: int, commands: list[str], scenes: list[str], warm: bool) -> None:
    trees = {"new": ROOT, "old": os.path.abspath(old)}
    out = os.path.join(tempfile.mkdtemp(prefix="rtcli-loading-"), "out.png")
    jobs = [(c, s) for c in commands for s in (scenes if c != "import" else ["-"])]
    print(f"\n{'command':<10} {'scene':<10} {'runs':>4} {'old s':>7} {'new s':>7} {'new/old':>8}")
    for command, scene in jobs:
        if warm:
            for tree in trees.values():
                whole(command, scene, tree, out)
        times = {"old": [], "new": []}
        for k in range(runs):
            for name in (("old", "new") if k % 2 == 0 else ("new", "old")):      # alternate who goes first
                times[name].append(whole(command, scene, trees[name], out))
        o, n = statistics.median(times["old"]), statistics.median(times["new"])
        print(f"{command:<10} {scene:<10} {runs:4d} {o:7.2f} {n:7.2f} {n / o:8.2f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs of each phase (the least is shown)")
    ap.add_argument("--old", help="another checkout of rtcli to compare whole commands with")
    ap.add_argument("--runs", type=int, default=7, help="whole-process runs of each, alternated")
    ap.add_argument("--commands", default="import,validate,render")
    ap.add_argument("--scenes", default="torus100k,spheres1k")
    ap.add_argument("--no-warm", dest="warm", action="store_false", help="skip the first run of each command")
    ap.add_argument("--no-phases", dest="phases", action="store_false")
    args = ap.parse_args()
    if args.phases:
        phases(args.repeat)
    if args.old:
        compare(args.old, args.runs, args.commands.split(","), args.scenes.split(","), args.warm)


if __name__ == "__main__":
    main()
