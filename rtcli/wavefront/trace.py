"""rayTrace() of notes 000 11.7, on whole arrays of rays.

    color = local(p)                                   (shade.py)
          + kr * trace(mirror ray)     if depth < max_depth and kr > 0
          + kt * trace(refracted ray)  if depth < max_depth and kt > 0 and no total internal reflection

Each branch recurses on the compacted subset of rays that need it. Colors are (3, n).
"""

from __future__ import annotations

import numpy as np

from rtcli.core.scene import Scene
from rtcli.core.vec import reflect, refract, unit
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit, surface
from rtcli.wavefront.rays import Rays
from rtcli.wavefront.shade import local


def trace(scene: Scene, rays: Rays, depth: int, stats: Stats) -> np.ndarray:
    """Color seen along each ray; depth 1 is the primary ray."""
    color = np.repeat(np.asarray(scene.background, float)[:, None], len(rays), axis=1)
    hits = find_first_hit(scene, rays)
    seen = np.flatnonzero(np.isfinite(hits.t))
    if len(seen):
        color[:, seen] = shade(scene, rays[seen], surface(scene, rays[seen], hits[seen]), depth, stats)
    return color


def shade(scene: Scene, rays: Rays, s, depth: int, stats: Stats) -> np.ndarray:
    """rtShade: the local term plus the mirror and refracted rays (global term)."""
    color = local(scene, rays, s, stats)
    if depth >= scene.settings.max_depth:
        return color
    table, D = scene.materials, np.array(unit(*rays.d))
    eps = scene.offset * s.ng                            # step off the surface, to the ray's side
    mirror = np.flatnonzero(table.mirror[s.material])
    if len(mirror):
        stats.reflected += len(mirror)
        ms = np.array(reflect(*D[:, mirror], *s.n[:, mirror]))      # ms = d - 2 (d.n) n
        reflected = trace(scene, Rays(s.p[:, mirror] + eps[:, mirror], ms), depth + 1, stats)
        color[:, mirror] += table.kr[s.material[mirror]].T * reflected
    clear = np.flatnonzero(table.clear[s.material])
    if len(clear):
        ior = table.ior[s.material[clear]]
        eta = np.where(s.entering[clear], 1.0 / ior, ior)  # 1 -> ior entering, ior -> 1 leaving
        *t_dir, tir = refract(*D[:, clear], *s.n[:, clear], eta)
        go = clear[~tir]
        stats.refracted += len(go)
        if len(go):
            rays_t = Rays(s.p[:, go] - eps[:, go], np.array(t_dir)[:, ~tir])
            color[:, go] += table.kt[s.material[go]].T * trace(scene, rays_t, depth + 1, stats)
    return color
