"""The local term of the shading equation (SCENE_FORMAT.md; notes 000 11.7, 002, 004):

    emission + ka Ia T + sum over lights not in shadow with N.L > 0:
                         att(r) I (kd T (N.L) + ks spec)

spec = max(0, R.V)^n with R = 2(N.L)N - L (phong), or max(0, N.H)^n with
H = norm(L + V) (blinn). Products of colors are per channel.
"""

from __future__ import annotations

import numpy as np

from rtcli.core.scene import Scene
from rtcli.core.vec import dot, normalize
from rtcli.stats import Stats
from rtcli.wavefront.intersect import Surface, occluded
from rtcli.wavefront.rays import Rays


def specular(N, L, V, NL, NV, n, model: str) -> np.ndarray:
    """spec for unit N, L, V (NL = N.L, NV = N.V) and exponents n.

    phong: R.V with R = 2(N.L)N - L, so R.V = 2(N.L)(N.V) - L.V; blinn: N.H, H = norm(L + V).
    """
    if model == "blinn":
        H = L + V
        cos = dot(N, H) / np.sqrt(dot(H, H))
    else:
        cos = 2 * NL * NV - dot(L, V)
    return np.maximum(cos, 0) ** n


def local(scene: Scene, rays: Rays, s: Surface, stats: Stats) -> np.ndarray:
    """Emission, ambient and direct light at each surface point."""
    m, table = s.material, scene.materials
    kd_T, ks, n = table.kd[m] * s.texture, table.ks[m], table.n[m]
    color = table.emission[m] + table.ka[m] * scene.ambient * s.texture
    V = -normalize(rays.direction)
    NV = dot(s.n, V)
    shiny = table.shiny[m]                               # spec is only worked out where ks > 0
    start = s.p + scene.offset * s.ng                    # feelers leave from the lit side
    for light in scene.lights:
        points = light.sample_points(s.p)
        for lp in points:
            to_light = lp - s.p
            r = np.sqrt(dot(to_light, to_light))
            L = to_light / r[:, None]
            NL = dot(s.n, L)
            lit = np.flatnonzero(NL > 0)                 # N.L <= 0: no contribution (004, case 2)
            stats.shadow += len(lit)
            lit = lit[~occluded(scene, start[lit], lp[lit])]
            weight = light.attenuate(r[lit]) * light.spot_factor(L[lit]) / len(points)
            color[lit] += (weight * NL[lit])[:, None] * light.color * kd_T[lit]
            hl = lit[shiny[lit]]
            if len(hl):
                spec = specular(s.n[hl], L[hl], V[hl], NL[hl], NV[hl], n[hl], scene.settings.specular)
                w = weight[shiny[lit]] * spec
                color[hl] += w[:, None] * light.color * ks[hl]
    return color
