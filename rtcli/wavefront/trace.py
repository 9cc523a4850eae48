"""rayTrace() of notes 000 11.7, on whole arrays of rays.

    color = local(p)                                   (shade.py)
          + wr * trace(mirror ray)     if depth < max_depth and wr > 0
          + wt * trace(refracted ray)  if depth < max_depth and wt > 0 (none past the critical angle)

wr and wt are the material's kr and kt, scaled by Fresnel's equations if it asks for them, and
with kt moved to the mirror ray at total internal reflection if the scene asks for that
(core/dielectric.py). Adaptive depth control (docs/scene-format.md, render: adc_bailout): each ray
carries its path weight, the product of the wr or wt of every surface before it (per channel,
the primary's 1), and a secondary ray whose path weight is below adc_bailout in every channel is
not traced. Each branch recurses on the compacted subset of rays that need it. Every
ray carries the media it is inside (Media), for Snell's n1 / n2. Colors are (3, n).
An optional recorder (`log`, a Log) is shown every quantity as it is computed and makes a
recorder for each subset of secondary rays; it changes nothing it sees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.dielectric import fresnel, indices, refracted_media, split
from rtcli.core.scene import Scene
from rtcli.core.shading import path_weight
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


class Log:
    """A recorder: what trace() and shade.local() show it, for the rays at hand (arrays over them).
    This base ignores everything; rtcli/inspect/explain.py keeps every term of one ray, rtcli/inspect/views.py
    how deep each pixel's rays go. `part` and `child` give the recorder of a subset of the rays:
    those that hit (`seen`), and those that spawn a reflected or refracted ray (`rows`)."""

    def rays(self, rays: Rays, depth: int, hits) -> None:
        """The rays traced at this depth and their first hits."""

    def surface(self, seen: np.ndarray, s) -> None:
        """The surface (intersect.Surface) where the rays `seen` hit."""

    def part(self, seen: np.ndarray) -> "Log | None":
        return self

    def ambient(self, color: np.ndarray) -> None:
        """emission + ka Ia T at each hit."""

    def light(self, index, cell, q, L, r, NL, start, through, lit, terms, hl, cos, shine) -> None:
        """Light `index`'s sample `cell` seen from each hit (shade.local's names)."""

    def glass(self, rows, n1, n2, cos_i, R, tir) -> None:
        """Snell's indices, the cosine of incidence, Fresnel's R and total internal reflection."""

    def child(self, rows: np.ndarray, kind: str, weights: np.ndarray) -> "Log | None":
        return self

    def bailout(self, rows: np.ndarray, kind: str, weights: np.ndarray, path: np.ndarray) -> None:
        """The reflected or refracted rays of `rows` not traced: their path weight is below adc_bailout."""

    def color(self, color: np.ndarray) -> None:
        """The color returned for each ray."""


def trace(scene: Scene, rays: Rays, depth: int, stats: Stats, media: Media | None = None,
          log: Log | None = None, path: np.ndarray | None = None) -> np.ndarray:
    """Color seen along each ray; depth 1 is the primary ray (in the scene's medium, path weight 1)."""
    media = media or Media.none(scene.settings.max_depth, len(rays))
    path = np.ones((3, len(rays))) if path is None else path
    color = np.repeat(np.asarray(scene.background, float)[:, None], len(rays), axis=1)
    hits = find_first_hit(scene, rays)
    seen = np.flatnonzero(np.isfinite(hits.t))
    if log:
        log.rays(rays, depth, hits)
    if len(seen):
        s = surface(scene, rays[seen], hits[seen])
        if log:
            log.surface(seen, s)
        color[:, seen] = shade(scene, rays[seen], s, depth, stats, media[seen], log and log.part(seen), path[:, seen])
    if log:
        log.color(color)
    return color


def shade(scene: Scene, rays: Rays, s, depth: int, stats: Stats, media: Media, log: Log | None = None,
          path: np.ndarray | None = None) -> np.ndarray:
    """rtShade: the local term plus the mirror and refracted rays (global term)."""
    color = local(scene, rays, s, stats, log)
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
        if log:
            log.glass(glass, n1, n2, -dot(*D[:, glass], *s.n[:, glass]), R, tir)
    path = np.ones((3, len(rays))) if path is None else path
    mirror = followed(scene, wr, path, "reflected", log)
    if len(mirror):
        stats.reflected += len(mirror)
        ms = np.array(reflect(*D[:, mirror], *s.n[:, mirror]))      # ms = d - 2 (d.n) n
        reflected = trace(scene, Rays(s.p[:, mirror] + eps[:, mirror], ms), depth + 1, stats, media[mirror],
                          log and log.child(mirror, "reflected", wr[:, mirror]), path[:, mirror] * wr[:, mirror])
        color[:, mirror] += wr[:, mirror] * reflected
    go = followed(scene, wt[:, glass], path[:, glass], "refracted", log, glass) if len(glass) else glass
    if len(go):
        rows = glass[go]
        stats.refracted += len(rows)
        inside, out_ior = media[rows], np.empty((len(media.ior), len(rows)))
        count = refracted_media(inside.ior, inside.count, table.ior[s.material[rows]], s.entering[rows], out_ior)
        rays_t = Rays(s.p[:, rows] - eps[:, rows], np.array(t_dir)[:, go])
        color[:, rows] += wt[:, rows] * trace(scene, rays_t, depth + 1, stats, Media(out_ior, count),
                                              log and log.child(rows, "refracted", wt[:, rows]),
                                              path[:, rows] * wt[:, rows])
    return color


def followed(scene: Scene, w: np.ndarray, path: np.ndarray, kind: str, log: Log | None,
             rows: np.ndarray | None = None) -> np.ndarray:
    """Which of the secondary rays of weights w (3, n) are traced: those with w > 0 whose path weight
    path x w is at least adc_bailout in some channel. The recorder is shown the others with w > 0."""
    spawned = w.max(axis=0) > 0
    *weights, traced = path_weight(*path, *w, scene.settings.adc_bailout)
    kept = spawned & traced
    if log and (spawned & ~kept).any():
        cut = np.flatnonzero(spawned & ~kept)
        log.bailout(cut if rows is None else rows[cut], kind, w[:, cut], np.array(weights)[:, cut])
    return np.flatnonzero(kept)
