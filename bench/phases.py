"""One render of a scene file, timed phase by phase as `rtcli render` runs them, with peak memory.

    python bench/phases.py SCENE.yaml OUT.png [--width 640 --height 480 --workers 2 --engine auto]

Prints one line of JSON: the wall-clock seconds of each phase, from the process's start:
start (Python and rtcli imported), load (the scene file read and built), build (the engine
readied: the BVH, the packed scene, its machine code), trace (the tiles, in worker processes),
write (the PNG); the CPU seconds of this process and of its workers; and the peak resident
memory of this process and of the largest worker (`ru_maxrss`), in MB. bench/run.py runs it
for the big scenes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time

STARTED = time.perf_counter()

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from rtcli.rendering import engine as engines  # noqa: E402  (timed: the start phase)
from rtcli.rendering import tiles  # noqa: E402
from rtcli.rendering.writer import write_images  # noqa: E402
from rtcli.scenefile.load import load_scene  # noqa: E402
from rtcli.stats import Stats  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--engine", default="auto")
    args = ap.parse_args()
    marks = {"start": time.perf_counter()}
    scene = load_scene(args.scene)
    marks["load"] = time.perf_counter()
    job = tiles.Job(args.width, args.height, engine=args.engine)
    todo, traced = tiles.plan(scene, job)
    engine, _ = engines.prepare(scene, job, traced)
    marks["build"] = time.perf_counter()
    stats = Stats()
    image = tiles.assemble(job, len(todo), tiles._map_tiles(scene, engine, job, todo, args.workers), stats)
    marks["trace"] = time.perf_counter()
    write_images([(args.out, image)])
    marks["write"] = time.perf_counter()
    self, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    previous, phases = STARTED, {}
    for name, at in marks.items():
        phases[name] = round(at - previous, 3)
        previous = at
    print(json.dumps({"phases": phases, "total": round(previous - STARTED, 3), "rays": stats.total,
                      "engine": "compiled" if engine else "numpy",
                      "cpu": round(self.ru_utime + self.ru_stime, 3), "workers_cpu": round(children.ru_utime +
                                                                                          children.ru_stime, 3),
                      "peak_mb": round(self.ru_maxrss / 1024), "worker_peak_mb": round(children.ru_maxrss / 1024)}))


if __name__ == "__main__":
    main()
