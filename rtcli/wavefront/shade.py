"""The local term of the shading equation on arrays of hits (docs/scene-format.md, Shading):

    emission + ka Ia T + sum over lights not in shadow with N.L > 0:
                         att(r) I (kd T (N.L) + ks spec)

The formulas are the kernels of rtcli/core/shading.py and rtcli/core/lights.py; this
module chooses what to compute for which hits: only the lit rows get a shadow feeler,
only the shiny ones a specular term. A feeler brings back how much of the light gets
through (transmittance: 0 in a full shadow, kt per surface of a `shadow: filter` object).
"""

from __future__ import annotations

import numpy as np

from rtcli.core.lights import COLOR, sample_point, toward, weight
from rtcli.core.scene import Scene
from rtcli.core.shading import ambient, diffuse, specular, specular_cos
from rtcli.core.vec import dot, unit
from rtcli.stats import Stats
from rtcli.wavefront.intersect import Surface, transmittance
from rtcli.wavefront.rays import Rays


def local(scene: Scene, rays: Rays, s: Surface, stats: Stats, log=None) -> np.ndarray:
    """Emission, ambient and direct light at each surface point: colors (3, n). `log`: a
    recorder (wavefront/trace.py) shown each term."""
    m, table, T, N = s.material, scene.materials, s.texture, s.n
    color = np.array(ambient(table, m, scene.ambient, *T))
    if log:
        log.ambient(color)
    V = -np.array(unit(*rays.d))
    NV = dot(*N, *V)
    shiny = table.shiny[m]                               # spec is only worked out where ks > 0
    base = s.p if s.lift is None else s.p + s.lift       # shadow_terminator: offset moves them (Hanika)
    start = base + scene.offset * s.ng                   # feelers leave from the lit side
    blinn = scene.settings.specular == "blinn"
    for index, (light, row) in enumerate(zip(scene.lights, scene.light_rows)):
        I = row[COLOR:COLOR + 3]
        for cell in range(light.samples):
            q = np.array(np.broadcast_arrays(*sample_point(row, cell, *s.p), s.p[0]))[:3]
            *L, r = toward(*q, *s.p)
            L = np.array(L)
            NL = dot(*N, *L)
            lit = np.flatnonzero(NL > 0)                 # N.L <= 0: no contribution (004, case 2)
            stats.shadow += len(lit)
            through = transmittance(scene, start[:, lit], q[:, lit])        # 0 in shadow, 1 in the open
            reach = through.max(axis=0) > 0
            lit, I_lit = lit[reach], I[:, None] * through[:, reach]
            w = weight(row, r[lit], *L[:, lit], light.samples)
            terms = diffuse(table, m[lit], I_lit, w, NL[lit], *T[:, lit])
            color[:, lit] += terms
            spec = shiny[lit]
            hl = lit[spec]
            cos = shine = None
            if len(hl):
                cos = specular_cos(blinn, *N[:, hl], *L[:, hl], *V[:, hl], NL[hl], NV[hl])
                shine = np.array(specular(table, m[hl], I_lit[:, spec], w[spec], cos))
                color[:, hl] += shine
            if log:
                log.light(index, cell, q, L, r, NL, start, through, lit, np.array(terms), hl, cos, shine)
    return color
