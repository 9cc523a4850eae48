"""Why a pixel has its color: the ray tree of one pixel, term by term (docs/debugging.md).

`explain_pixel` traces the pixel's rays with the numpy engine (rtcli/wavefront/trace.py) and a
Recorder, which the engine shows every quantity as it computes it: the hit, the surface, the
ambient term, each light sample's feeler and terms, Fresnel's R and Snell's indices, each
secondary ray's weight and color. The numbers in the tree are therefore the render's own, and
a node's terms add up, in the engine's order, to its color:

    color = emission + ka Ia T + sum over light samples (diffuse + specular)
          + wr x reflected + wt x refracted                       (docs/scene-format.md, Shading)

`RayNode.total()` recomputes that sum from the terms shown, so a tree that hid a term would
not add up (raytree.py). With n x n samples per pixel the pixel is the mean of the samples' trees.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.core.display import to_8bit
from rtcli.core.jitter import sample_positions
from rtcli.core.lights import COLOR, POSITION, attenuation, spot_factor
from rtcli.core.scene import Scene
from rtcli.errors import RtcliError
from rtcli.inspect.budget import MAX_NODES, Levels, Summary, deepest_shown
from rtcli.inspect.raytree import Bailout, Explanation, Feeler, Glass, Hit, LightSample, LightTerm, RayNode
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.rays import Rays, camera_rays
from rtcli.wavefront.trace import Log, trace


class Recorder(Log):
    """The engine's recorder (wavefront/trace.py) for one ray: fills a RayNode. Rays deeper than
    `shown_to` (None: none) are summarised (budget.py)."""

    def __init__(self, scene: Scene, node: RayNode, shown_to: int | None = None, left: list | None = None):
        self.scene, self.node, self.shown_to, self.left = scene, node, shown_to, left

    def rays(self, rays: Rays, depth: int, hits) -> None:
        self.node.origin, self.node.direction = rays.o[:, 0].copy(), rays.d[:, 0].copy()
        self._t = float(hits.t[0])

    def surface(self, seen, s) -> None:
        scene, k, m = self.scene, int(s.obj[0]), int(s.material[0])
        obj, table = scene.objects[k], scene.materials
        self.node.hit = Hit(obj.id, obj.name, obj.kind, self._t, s.p[:, 0].copy(), s.n[:, 0].copy(),
                            s.ng[:, 0].copy(), bool(s.entering[0]), m, material_name(table, m),
                            coefficients(table, m), s.texture[:, 0].copy())
        self.node.emission = table.emission[m].copy()
        self.node.ambient_term = table.ka[m] * scene.ambient * s.texture[:, 0]
        if self.node.depth >= scene.settings.max_depth:
            self.node.stopped = bool(table.mirror[m] or table.clear[m] or table.fresnel[m])

    def part(self, seen) -> Recorder | None:
        return self if len(seen) else None

    def ambient(self, color) -> None:
        self.node.ambient = color[:, 0].copy()

    def light(self, index, cell, q, L, r, NL, start, through, lit, terms, hl, cos, shine) -> None:
        scene = self.scene
        row, light = scene.light_rows[index], scene.lights[index]
        if cell == 0:
            kind = "area" if light.area_u is not None else "spot" if light.spot_direction is not None else "point"
            self.node.lights.append(LightTerm(index + 1, kind, row[POSITION:POSITION + 3].copy(),
                                              row[COLOR:COLOR + 3].copy()))
        Lk, rk = L[:, 0].copy(), float(r[0])
        att, spot = float(attenuation(row, rk)), float(spot_factor(row, *Lk))
        sample = LightSample(cell, q[:, 0].copy(), Lk, rk, float(NL[0]), att, spot, att * spot / light.samples)
        if NL[0] > 0:
            sample.feeler = self._feeler(start[:, 0], q[:, 0], through[:, 0])
        if len(lit):
            sample.diffuse = terms[:, 0].copy()
            sample.terms.append(sample.diffuse)
        if len(hl):
            sample.cos, sample.specular = float(cos[0]), shine[:, 0].copy()
            sample.terms.append(sample.specular)
        self.node.lights[-1].samples.append(sample)

    def _feeler(self, start, q, through) -> Feeler:
        """The feeler start + t (q - start), 0 < t < 1, and the first object on it that casts shadows."""
        scene, f = self.scene, Feeler(start.copy(), through.copy())
        if f.state != "clear":
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                hits = find_first_hit(scene, Rays(start[:, None], (q - start)[:, None]), 0.0, 1.0, casters=True)
            if np.isfinite(hits.t[0]):
                obj = scene.objects[int(hits.obj[0])]
                f.blocker, f.blocker_name, f.blocker_t = obj.id, obj.name, float(hits.t[0])
        return f

    def glass(self, rows, n1, n2, cos_i, R, tir) -> None:
        n1, n2, cos_i, tir = float(n1[0]), float(n2[0]), float(cos_i[0]), bool(tir[0])
        theta_i = math.degrees(math.acos(min(1.0, max(-1.0, cos_i))))
        sin_t = n1 / n2 * math.sin(math.radians(theta_i))
        self.node.glass = Glass(n1, n2, cos_i, theta_i, None if tir else math.degrees(math.asin(min(1.0, sin_t))),
                                float(R[0]), tir, self.node.hit.coefficients["fresnel"])

    def child(self, rows, kind: str, weights) -> Recorder | Summary:
        if self.left is not None:                         # a first pass, given up past the budget
            self.left[0] -= 1
            if self.left[0] < 0:
                raise OverBudget
        node = RayNode(kind, self.node.depth + 1, np.zeros(3), np.zeros(3), weights[:, 0].copy())
        self.node.children.append(node)
        if self.shown_to is not None and node.depth > self.shown_to:
            return Summary(node)
        return Recorder(self.scene, node, self.shown_to, self.left)

    def bailout(self, rows, kind: str, weights, path) -> None:
        self.node.bailouts.append(Bailout(kind, weights[:, 0].copy(), path[:, 0].copy(),
                                          self.scene.settings.adc_bailout))

    def color(self, color) -> None:
        self.node.value = color[:, 0].copy()


def material_name(table, m: int) -> str:
    name = getattr(table.materials[m], "name", "")
    return name or ("(the default)" if m == 0 else "(inline)")


def coefficients(table, m: int) -> dict:
    mat = table.materials[m]
    return {"ka": table.ka[m], "kd": table.kd[m], "ks": table.ks[m], "n": float(table.shininess[m]),
            "emission": table.emission[m], "kr": table.kr[m], "kt": table.kt[m], "ior": float(table.ior[m]),
            "fresnel": bool(table.fresnel[m]), "shadow": {True: "on", False: "off"}.get(mat.shadow, mat.shadow),
            "texture": type(mat.texture).__name__.lower() if mat.texture is not None else None}


def trace_one(scene: Scene, x: float, y: float, width: int, height: int, max_nodes: int = MAX_NODES) -> RayNode:
    """The tree of the primary ray through image position (x, y) of a width x height image, its
    rays past the node budget summarised (budget.py): when the whole tree does not fit, its rays
    of each depth are counted first."""
    rays = camera_rays(scene.camera(width, height), np.array([x]), np.array([y]), width, height)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        root = RayNode("primary", 1, rays.o[:, 0], rays.d[:, 0])
        try:
            trace(scene, rays, 1, Stats(), log=Recorder(scene, root, left=[max_nodes - 1]))
            return root
        except OverBudget:
            pass
        levels = Levels()
        trace(scene, rays, 1, Stats(), log=levels)
        root = RayNode("primary", 1, rays.o[:, 0], rays.d[:, 0])
        trace(scene, rays, 1, Stats(), log=Recorder(scene, root, deepest_shown(levels.count, max_nodes)))
    return root


class OverBudget(Exception):
    """The tree has more rays than the budget: a first pass gives up."""


def explain_pixel(model, x: int, y: int, width: int, height: int, gamma: bool = False,
                  max_nodes: int = MAX_NODES) -> Explanation:
    """The ray trees of pixel (x, y) of a width x height image of a scene model readied for the numpy
    engine, with its own samples and max_depth: one tree per sample, and the pixel their mean. Each
    tree shows at most max_nodes rays in full, the deeper ones summarised."""
    settings = model.settings
    n = settings.samples
    xs, ys = sample_positions(np.array([x]), np.array([y]), n)
    trees = [trace_one(model, float(xs[k, 0]), float(ys[k, 0]), width, height, max_nodes) for k in range(n * n)]
    value = np.array([t.value for t in trees]).reshape(n * n, 1, 3).mean(axis=0)     # as render_tile averages
    return Explanation(int(x), int(y), width, height, n, np.column_stack([xs[:, 0], ys[:, 0]]), trees, value[0],
                       to_8bit(value, gamma)[0], np.asarray(model.background, float), settings.specular, gamma)


def check_pixel(x, y, width: int, height: int) -> None:
    """RtcliError unless (x, y) is a pixel of a width x height image (whole numbers, from 0)."""
    for name, value in (("x", x), ("y", y)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise RtcliError(f"the pixel's {name} must be a whole number, got {value!r}")
    if not (0 <= x < width and 0 <= y < height):
        raise RtcliError(f"pixel ({x}, {y}) is outside the {width}x{height} image: x goes from 0 to {width - 1}, "
                         f"y from 0 to {height - 1}")


__all__ = ["explain_pixel", "check_pixel", "Explanation", "RayNode", "Hit", "LightTerm", "LightSample", "Feeler", "Glass"]
