"""rayTrace() of notes 000 11.7, on whole arrays of rays.

    color = local(p)                                   (shade.py)
          + wr * trace(mirror ray)     if depth < max_depth and wr > 0
          + wt * trace(refracted ray)  if depth < max_depth and wt > 0 (none past the critical angle)

wr and wt are the material's kr and kt, scaled by Fresnel's equations if it asks for them, and
with kt moved to the mirror ray at total internal reflection if the scene asks for that
(core/dielectric.py). Each branch recurses on the compacted subset of rays that need it. Every
ray carries the media it is inside (Media), for Snell's n1 / n2. Colors are (3, n).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.dielectric import fresnel, indices, refracted_media, split
from rtcli.core.scene import Scene
from rtcli.core.vec import dot, reflect, refract, unit
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit, surface
from rtcli.wavefront.rays import Rays
from rtcli.wavefront.shade import local


@dataclass(frozen=True)
class Media:
    """The media each ray is inside (core/dielectric.py): their iors (D, n), innermost last, and
    how many each ray has."""

    ior: np.ndarray
    count: np.ndarray

    @staticmethod
    def none(depth: int, n: int) -> "Media":
        return Media(np.ones((depth, n)), np.zeros(n, dtype=np.int64))

    def __getitem__(self, which) -> "Media":
        return Media(self.ior[:, which], self.count[which])


def trace(scene: Scene, rays: Rays, depth: int, stats: Stats, media: Media | None = None) -> np.ndarray:
    """Color seen along each ray; depth 1 is the primary ray (in the scene's medium)."""
    media = media or Media.none(scene.settings.max_depth, len(rays))
    color = np.repeat(np.asarray(scene.background, float)[:, None], len(rays), axis=1)
    hits = find_first_hit(scene, rays)
    seen = np.flatnonzero(np.isfinite(hits.t))
    if len(seen):
        color[:, seen] = shade(scene, rays[seen], surface(scene, rays[seen], hits[seen]), depth, stats,
                               media[seen])
    return color


def shade(scene: Scene, rays: Rays, s, depth: int, stats: Stats, media: Media) -> np.ndarray:
    """rtShade: the local term plus the mirror and refracted rays (global term)."""
    color = local(scene, rays, s, stats)
    if depth >= scene.settings.max_depth:
        return color
    table, D = scene.materials, np.array(unit(*rays.d))
    eps = scene.offset * s.ng                            # step off the surface, to the ray's side
    wr, wt = table.kr[s.material].T.copy(), np.zeros((3, len(rays)))
    glass = np.flatnonzero(table.clear[s.material] | (table.fresnel[s.material] != 0))
    if len(glass):
        m, inside = s.material[glass], media[glass]
        n1, n2 = indices(inside.ior, inside.count, scene.settings.medium_ior, table.ior[m], s.entering[glass])
        eta = n1 / n2
        *t_dir, tir = refract(*D[:, glass], *s.n[:, glass], eta)
        R = fresnel(-dot(*D[:, glass], *s.n[:, glass]), eta)
        w_r, w_t = split(table, m, R, tir, scene.settings.total_internal_reflection == "reflect")
        wr[:, glass], wt[:, glass] = w_r, w_t
    mirror = np.flatnonzero(wr.max(axis=0) > 0)
    if len(mirror):
        stats.reflected += len(mirror)
        ms = np.array(reflect(*D[:, mirror], *s.n[:, mirror]))      # ms = d - 2 (d.n) n
        reflected = trace(scene, Rays(s.p[:, mirror] + eps[:, mirror], ms), depth + 1, stats, media[mirror])
        color[:, mirror] += wr[:, mirror] * reflected
    go = np.flatnonzero(wt[:, glass].max(axis=0) > 0) if len(glass) else glass
    if len(go):
        rows = glass[go]
        stats.refracted += len(rows)
        inside, out_ior = media[rows], np.empty((len(media.ior), len(rows)))
        count = refracted_media(inside.ior, inside.count, table.ior[s.material[rows]], s.entering[rows], out_ior)
        rays_t = Rays(s.p[:, rows] - eps[:, rows], np.array(t_dir)[:, go])
        color[:, rows] += wt[:, rows] * trace(scene, rays_t, depth + 1, stats, Media(out_ior, count))
    return color
