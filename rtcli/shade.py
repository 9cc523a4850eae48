"""The local term of the shading equation (SCENE_FORMAT.md; notes 000 11.7, 002, 004):

    emission + ka Ia T + sum over lights not in shadow with N.L > 0:
                         att(r) I (kd T (N.L) + ks spec)

spec = max(0, R.V)^n with R = 2(N.L)N - L (phong), or max(0, N.H)^n with
H = norm(L + V) (blinn). Products of colors are per channel.
"""

from __future__ import annotations

import numpy as np

from rtcli.intersect import Surface, occluded
from rtcli.rays import Rays
from rtcli.scene import Scene
from rtcli.stats import Stats
from rtcli.vec import dot, normalize


def specular(N, L, V, n, model: str) -> np.ndarray:
    """spec for unit N, L, V and exponents n."""
    if model == "blinn":
        cos = dot(N, normalize(L + V))                   # N.H
    else:
        NL = dot(N, L)
        cos = dot(2 * NL[:, None] * N - L, V)            # R.V
    return np.maximum(cos, 0) ** n


def local(scene: Scene, rays: Rays, s: Surface, stats: Stats) -> np.ndarray:
    """Emission, ambient and direct light at each surface point."""
    m, table = s.material, scene.materials
    kd_T = table.kd[m] * s.texture
    color = table.emission[m] + table.ka[m] * scene.ambient * s.texture
    V = -normalize(rays.direction)
    start = s.p + scene.offset * s.ng                    # feelers leave from the lit side
    for light in scene.lights:
        points = light.sample_points(s.p)
        for lp in points:
            to_light = lp - s.p
            r = np.sqrt(dot(to_light, to_light))
            L = to_light / r[:, None]
            NL = dot(s.n, L)
            lit = np.flatnonzero(NL > 0)
            stats.shadow += len(lit)
            lit = lit[~occluded(scene, start[lit], lp[lit])]
            spec = specular(s.n[lit], L[lit], V[lit], table.n[m[lit]], scene.settings.specular)
            weight = light.attenuate(r[lit]) * light.spot_factor(L[lit]) / len(points)
            color[lit] += (weight[:, None] * light.color) * (
                kd_T[lit] * NL[lit, None] + table.ks[m[lit]] * spec[:, None])
    return color
