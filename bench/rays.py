"""Rays per second on one core: rtcli's compiled engine beside Embree on the same rays.

torus100k at WIDTH x HEIGHT: the camera ray through every pixel's centre, and for each hit
that faces the light a shadow ray toward it: what rtcli's compiled engine traces on this
scene (it shades too; Embree only finds the hits). rtcli's rate is its whole trace over
the rays it counts (--stats' count); Embree's (embreex, rtcIntersect1 over a numpy array
of rays, one thread) is its two queries over the same count, in single precision as Embree
works. Both in this process, after a warm-up run; the median of --runs.

    python bench/rays.py [--width 1920] [--height 1080] [--runs 5]      # embreex from the 'bench' extra
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def rtcli_rate(width: int, height: int, runs: int) -> tuple[float, int]:
    """(rays per second, rays) of the compiled engine tracing every pixel once, one thread."""
    import rtcli
    from rtcli.compiled import Compiled
    from rtcli.stats import Stats
    model = rtcli.load_scene(os.path.join(HERE, "torus100k.yaml"), width=width, height=height).model
    engine, cam = Compiled(model, True), model.camera(width, height)
    jj, ii = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    x, y = ii.ravel() + 0.5, jj.ravel() + 0.5
    engine.trace_pixels(cam, x[:64], y[:64], width, height, Stats())          # loads the machine code
    times, stats = [], Stats()
    for _ in range(runs):
        stats = Stats()
        start = time.perf_counter()
        engine.trace_pixels(cam, x, y, width, height, stats)
        times.append(time.perf_counter() - start)
    rays = len(x) + stats.shadow + stats.reflected + stats.refracted       # trace_pixels counts what it spawns
    return rays / statistics.median(times), rays


def torus_triangles() -> np.ndarray:
    """(n, 3, 3) the torus's triangles as rtcli places them (mirrored in x), and the floor as two."""
    v, f = [], []
    with open(os.path.join(HERE, "torus100k.obj")) as obj:
        for line in obj:
            if line.startswith("v "):
                v.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    tris = np.array(v)[np.array(f)] * [-1, 1, 1]
    s = 1e4
    floor = np.array([[[-s, 0, -s], [s, 0, -s], [s, 0, s]], [[-s, 0, -s], [s, 0, s], [-s, 0, s]]])
    return np.concatenate([tris, floor])


def embree_rate(width: int, height: int, runs: int) -> tuple[float, int]:
    """(rays per second, rays) of Embree on the camera rays and the shadow rays of their hits."""
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    import rtcli
    from rtcli.wavefront.rays import camera_rays
    model = rtcli.load_scene(os.path.join(HERE, "torus100k.yaml"), width=width, height=height).model
    light = np.asarray(model.lights[0].position, dtype=float)
    tris = torus_triangles()
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, tris.astype(np.float32))
    jj, ii = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    rays = camera_rays(model.camera(width, height), ii.ravel() + 0.5, jj.ravel() + 0.5, width, height)
    o = np.ascontiguousarray(rays.o.T, dtype=np.float32)
    d = np.ascontiguousarray(rays.d.T, dtype=np.float32)
    scene.run(o[:64], d[:64])                                                   # builds the BVH
    times, count = [], 0
    for _ in range(runs):
        start = time.perf_counter()
        hit = scene.run(o, d, query="INTERSECT", output=1)
        prim, t = hit["primID"], hit["tfar"]
        seen = prim >= 0
        p = o[seen] + t[seen, None] * d[seen]
        e1, e2 = tris[prim[seen], 1] - tris[prim[seen], 0], tris[prim[seen], 2] - tris[prim[seen], 0]
        n = np.cross(e1, e2)
        n *= np.sign(np.sum(n * -d[seen], axis=1))[:, None]                  # facing the camera ray
        to_light = light - p
        lit = np.sum(n * to_light, axis=1) > 0
        start_points = (p[lit] + 1e-4 * n[lit] / np.linalg.norm(n[lit], axis=1)[:, None]).astype(np.float32)
        shadow_d = (light - start_points).astype(np.float32)
        scene.run(start_points, shadow_d, query="OCCLUDED", dists=np.ones(len(shadow_d), np.float32))
        times.append(time.perf_counter() - start)
        count = len(o) + len(shadow_d)
    return count / statistics.median(times), count


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=1920)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    rate, rays = rtcli_rate(args.width, args.height, args.runs)
    print(f"rtcli compiled, 1 thread: {rays:,} rays, {rate / 1e6:.2f} Mrays/s")
    try:
        import embreex  # noqa: F401
    except ImportError:
        print("Embree: embreex is not installed (pip install -e '.[bench]')")
        return
    e_rate, e_rays = embree_rate(args.width, args.height, args.runs)
    print(f"Embree (embreex), 1 thread: {e_rays:,} rays, {e_rate / 1e6:.2f} Mrays/s; rtcli / Embree {rate / e_rate:.2f}")


if __name__ == "__main__":
    main()
