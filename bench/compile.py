"""A cold compile of each compiled entry point: how long numba takes with an empty cache.

Each run is a fresh process with an empty cache folder of its own (RTCLI_CACHE_DIR, a new
temporary folder; RTCLI_MACHINE_CODE=0, so no machine code file is read or written) that
compiles one entry point, as a render or `rtcli warmup` would, and reports the seconds of
that compile: wall clock and CPU (user + sys of the process while it compiled, less
sensitive to other processes on a shared machine). The entry points:

    engine     the compiled engine's entry (compiled/tracing.py's trace_camera)
    walks      the numpy engine's BVH walks, over a mesh's triangles and over a tree of spheres
    build      the BVH build (core/bvh_build.py's levels)
    warmup     the whole `rtcli warmup` command as a process (machine code files written too)

The runs go round the entry points in turn (A B C A B C ...), `--runs` times, so that a
change in the machine's load falls on all of them; the table gives each one's median and
range. With --old DIR (another checkout of rtcli, say `git worktree add /tmp/old main`) each
entry point runs in this checkout and in DIR alternately, on this Python, each with its own
folder first on PYTHONPATH, and the table adds the medians' ratio new / old.

    python bench/compile.py [--runs 3] [--entries engine,walks,build,warmup] [--old DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ENTRIES = ("engine", "walks", "build", "warmup")


def compile_one(entry: str) -> dict:
    """In the child process: compile `entry` and time it (wall and CPU seconds)."""
    import numpy as np

    from rtcli.rendering.warmup import _scenes
    spheres, mesh = _scenes()
    wall, cpu = time.perf_counter(), time.process_time()
    if entry == "engine":
        from rtcli.compiled import Compiled
        Compiled(spheres, notes=lambda text: None)
    elif entry == "walks":
        from rtcli import wavefront
        from rtcli.compiled.walks import Walks
        for scene in (spheres, mesh):
            wavefront.build(scene)
            for call in Walks().calls(scene, *wavefront.walked(scene))[1]:
                call()
    elif entry == "build":
        from rtcli.core.bvh_build import levels, levels_args
        from rtcli.kernels import variants
        lo = np.random.default_rng(0).random((64, 3))
        variants.compiled(levels)(*levels_args(lo, lo + 0.1, 2, 12))
    return {"wall": time.perf_counter() - wall, "cpu": time.process_time() - cpu}


def run(entry: str, checkout: str) -> dict:
    """One cold compile of `entry` in a fresh process of `checkout`, with an empty cache."""
    with tempfile.TemporaryDirectory(prefix="rtcli-compile-") as cache:
        env = dict(os.environ, RTCLI_CACHE_DIR=cache, PYTHONPATH=checkout, RTCLI_NUMBA="1")
        if entry == "warmup":
            command = [sys.executable, "-m", "rtcli", "warmup"]
        else:
            env["RTCLI_MACHINE_CODE"] = "0"
            command = [sys.executable, os.path.abspath(__file__), "--child", entry]
        start = time.perf_counter()
        process = subprocess.Popen(command, env=env, cwd=cache, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   text=True)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        out, err = process.stdout.read(), process.stderr.read()
        process.stdout.close(), process.stderr.close()
        process.returncode = os.waitstatus_to_exitcode(status)
        if process.returncode != 0:
            raise SystemExit(f"{entry} in {checkout} failed ({process.returncode}):\n{err[-2000:]}")
    if entry == "warmup":
        return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime}
    return json.loads(out.strip().splitlines()[-1])


def table(results: dict, checkouts: list[str]) -> str:
    lines = []
    for entry, by_checkout in results.items():
        for figure in ("wall", "cpu"):
            cells = []
            for checkout in checkouts:
                values = [r[figure] for r in by_checkout[checkout]]
                cells.append(f"{statistics.median(values):7.1f} s ({min(values):.1f}-{max(values):.1f})")
            if len(checkouts) == 2:
                new, old = (statistics.median(r[figure] for r in by_checkout[c]) for c in checkouts)
                cells.append(f"new/old {new / old:.2f}")
            lines.append(f"{entry:8} {figure:5} " + "   ".join(cells))
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--entries", default=",".join(ENTRIES))
    parser.add_argument("--old", help="another checkout of rtcli to compare with")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(compile_one(args.child)))
        return
    entries = [e for e in args.entries.split(",") if e]
    unknown = set(entries) - set(ENTRIES)
    if unknown:
        parser.error(f"unknown entry points {sorted(unknown)}; known: {', '.join(ENTRIES)}")
    checkouts = [ROOT] + ([os.path.abspath(args.old)] if args.old else [])
    results = {e: {c: [] for c in checkouts} for e in entries}
    for k in range(args.runs):
        for entry in entries:
            for checkout in checkouts if k % 2 == 0 else checkouts[::-1]:
                results[entry][checkout].append(run(entry, checkout))
                r = results[entry][checkout][-1]
                print(f"run {k + 1}: {entry} ({'old' if checkout != ROOT else 'new'}): "
                      f"{r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU", file=sys.stderr, flush=True)
    print("cold compile, empty cache; medians of", args.runs, "runs (min-max)" + (
        f"; columns: this checkout, {args.old}" if args.old else ""))
    print(table(results, checkouts))


if __name__ == "__main__":
    main()
