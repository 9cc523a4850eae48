"""Why a pixel has its color: the ray tree of one pixel, term by term (docs/debugging.md).

`explain` traces the pixel's rays with the numpy engine (rtcli/wavefront/trace.py) and a
Recorder, which the engine shows every quantity as it computes it: the hit, the surface, the
ambient term, each light sample's feeler and terms, Fresnel's R and Snell's indices, each
secondary ray's weight and color. The numbers in the tree are therefore the render's own, and
a node's terms add up, in the engine's order, to its color:

    color = emission + ka Ia T + sum over light samples (diffuse + specular)
          + wr x reflected + wt x refracted                       (docs/scene-format.md, Shading)

`RayNode.total()` recomputes that sum from the terms shown, so a tree that hid a term would
not add up. With n x n samples per pixel the pixel is the mean of the samples' trees.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from rtcli.core.lights import COLOR, POSITION, attenuation, spot_factor
from rtcli.core.scene import Scene
from rtcli.errors import RtcliError, one_line
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.rays import Rays
from rtcli.wavefront.trace import Log

Color = np.ndarray                 # (3,) float64


@dataclass
class Hit:
    """Where a ray meets the scene, and what the surface is made of there."""

    object: int                    # the object's id (as in the signature), 1, 2, ...
    name: str
    shape: str
    t: float                       # the hit is origin + t direction
    point: np.ndarray
    normal: np.ndarray             # unit shading normal, turned toward the ray
    geometric: np.ndarray          # unit geometric normal, same side
    entering: bool                 # the ray arrives from the outside
    material: int                  # row of the material table (0: the default material)
    material_name: str
    coefficients: dict             # ka, kd, ks, n, emission, kr, kt, ior, fresnel, shadow
    texture: np.ndarray            # T (1, 1, 1 without a texture)


@dataclass
class Feeler:
    """The shadow feeler from the hit toward one light point."""

    start: np.ndarray              # the hit point moved off the surface, toward the lit side
    through: np.ndarray            # how much of the light gets through per channel (0 blocked, 1 clear)
    blocker: int | None = None     # id of the first object crossed that casts shadows
    blocker_name: str = ""
    blocker_t: float | None = None  # along start + t (light point - start), 0 < t < 1

    @property
    def state(self) -> str:
        return "clear" if self.through.min() >= 1 else "blocked" if self.through.max() <= 0 else "filtered"


@dataclass
class LightSample:
    """One point of a light (a point light has one; an area light n x n) as seen from the hit."""

    cell: int
    point: np.ndarray              # the light point q
    L: np.ndarray                  # unit vector toward q
    r: float                       # distance to q
    NL: float
    attenuation: float             # 1 / (c0 + c1 r + c2 r^2)
    spot: float                    # the spot factor (1 for other lights)
    weight: float                  # attenuation x spot / samples
    feeler: Feeler | None = None   # None when N.L <= 0: the point faces away, no feeler is cast
    diffuse: Color = field(default_factory=lambda: np.zeros(3))     # w (N.L) I' kd T, I' = I x through
    specular: Color = field(default_factory=lambda: np.zeros(3))    # w max(0, cos)^n I' ks
    cos: float | None = None       # R.V (phong) or N.H (blinn), when the material has ks > 0 and is lit
    terms: list = field(default_factory=list)                       # the terms added, in order

    @property
    def lit(self) -> bool:
        return bool(self.terms)


@dataclass
class LightTerm:
    """A light's share of the local color: the sum of its samples' terms."""

    index: int                     # 1, 2, ... in the scene file's order
    kind: str                      # point, spot or area
    position: np.ndarray
    color: np.ndarray              # I
    samples: list[LightSample] = field(default_factory=list)

    def diffuse(self) -> Color:
        return sum((s.diffuse for s in self.samples), np.zeros(3))

    def specular(self) -> Color:
        return sum((s.specular for s in self.samples), np.zeros(3))


@dataclass
class Glass:
    """Snell's and Fresnel's numbers at a surface with kt > 0 or fresnel: true."""

    n1: float                      # index of the medium the ray is in
    n2: float                      # index of the medium beyond the surface
    cos_i: float
    theta_i: float                 # degrees, from the normal
    theta_t: float | None          # degrees; None past the critical angle
    R: float                       # Fresnel's reflectance (1 at total internal reflection)
    tir: bool                      # total internal reflection
    fresnel: bool = True           # the weights are kr R and kt (1 - R); else kr and kt as given


@dataclass
class RayNode:
    """A ray of the tree, what it hit and the terms of its color."""

    kind: str                      # primary, reflected or refracted
    depth: int                     # 1 for the primary ray
    origin: np.ndarray
    direction: np.ndarray          # as traced (not always unit): the hit is origin + t direction
    weight: Color | None = None    # what the parent multiplies this ray's color by (wr or wt)
    hit: Hit | None = None         # None: the ray misses everything and sees the background
    ambient: Color | None = None   # emission + ka Ia T, as the engine computed it
    emission: Color | None = None
    ambient_term: Color | None = None   # ka Ia T alone
    lights: list[LightTerm] = field(default_factory=list)
    glass: Glass | None = None
    children: list[RayNode] = field(default_factory=list)
    stopped: bool = False          # max_depth reached where the material would spawn rays
    value: Color | None = None     # the color the engine returned for this ray

    def local(self) -> Color:
        """emission + ka Ia T + every light sample's diffuse and specular terms, in the engine's order."""
        color = np.array(self.ambient, dtype=float)
        for light in self.lights:
            for s in light.samples:
                for term in s.terms:
                    color += term
        return color

    def total(self) -> Color:
        """The ray's color from the terms shown: the background on a miss, else local + each
        child's weight times its total."""
        if self.hit is None:
            return np.array(self.value, dtype=float)
        color = self.local()
        for child in self.children:
            color += child.weight * child.total()
        return color

    def walk(self):
        yield self
        for child in self.children:
            yield from child.walk()

    def __str__(self) -> str:
        """The ray's tree as text, as `rtcli explain` prints it."""
        from rtcli.explain_text import node_lines
        return "\n".join(node_lines(self, lambda text, role: text))

    def __repr__(self) -> str:
        what = "misses" if self.hit is None else f"hits #{self.hit.object} {one_line(self.hit.name) or '(unnamed)'}"
        return f"<rtcli RayNode: {self.kind} ray, depth {self.depth}, {what}; print() shows its tree>"

    def _repr_pretty_(self, p, cycle: bool) -> None:
        """IPython and Jupyter show the tree (IPython's pretty-printing protocol)."""
        p.text(str(self))


@dataclass
class Explanation:
    """The ray trees of a pixel's samples and the pixel's color, their mean."""

    x: int
    y: int
    width: int
    height: int
    samples: int                   # n: n x n samples per pixel
    positions: np.ndarray          # (n^2, 2) the samples' image coordinates
    trees: list[RayNode]
    value: Color                   # the pixel as a float, before 8-bit rounding
    byte: np.ndarray               # the pixel in the 8-bit image
    background: Color
    specular: str = "phong"        # the scene's specular model: phong (R.V) or blinn (N.H)
    gamma: bool = False

    def to_dict(self, sample: int | None = None) -> dict:
        """Plain data (lists, numbers, strings) for JSON: every sample, or the one asked for."""
        chosen = range(len(self.trees)) if sample is None else [sample]
        return {"pixel": [self.x, self.y], "image": [self.width, self.height],
                "samples_per_pixel": self.samples ** 2, "value": self.value, "byte": self.byte,
                "gamma": self.gamma,
                "samples": [{"sample": k, "position": self.positions[k], "ray": _plain(self.trees[k])}
                            for k in chosen]}

    def json(self, sample: int | None = None) -> str:
        return json.dumps(_plain(self.to_dict(sample)), indent=2)

    def text(self, sample: int | None = 0, style=None) -> str:
        """The tree as text; `style(text, role)` may color it (roles: ray, miss, term, sum, note)."""
        from rtcli.explain_text import format_explanation
        return format_explanation(self, sample, style or (lambda text, role: text))

    def __str__(self) -> str:
        return self.text(None if len(self.trees) == 1 else 0)

    def __repr__(self) -> str:
        from rtcli.explain_text import vec
        return (f"<rtcli Explanation of pixel ({self.x}, {self.y}) of {self.width}x{self.height} = {vec(self.value)} "
                f"-> 8-bit {tuple(int(b) for b in self.byte)}; print() shows its tree>")

    def _repr_pretty_(self, p, cycle: bool) -> None:
        """IPython and Jupyter show the tree, as `rtcli explain` prints it (IPython's
        pretty-printing protocol), instead of the dataclass's fields."""
        p.text(str(self))


class Recorder(Log):
    """The engine's recorder (wavefront/trace.py) for one ray: fills a RayNode."""

    def __init__(self, scene: Scene, node: RayNode):
        self.scene, self.node = scene, node

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

    def child(self, rows, kind: str, weights) -> Recorder:
        node = RayNode(kind, self.node.depth + 1, np.zeros(3), np.zeros(3), weights[:, 0].copy())
        self.node.children.append(node)
        return Recorder(self.scene, node)

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


def trace_one(scene: Scene, x: float, y: float, width: int, height: int) -> RayNode:
    """The tree of the primary ray through image position (x, y) of a width x height image."""
    from rtcli.render import camera_rays
    from rtcli.wavefront.trace import trace
    rays = camera_rays(scene.camera(width, height), np.array([x]), np.array([y]), width, height)
    root = RayNode("primary", 1, rays.o[:, 0], rays.d[:, 0])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        trace(scene, rays, 1, Stats(), log=Recorder(scene, root))
    return root


def explain(scene, x: int, y: int, *, width: int | None = None, height: int | None = None,
            samples: int | None = None, max_depth: int | None = None, gamma: bool = False,
            bvh: bool = True) -> Explanation:
    """The ray trees of pixel (x, y) (column from the left, row from the top) of a Scene, or of
    what rtcli.load_scene takes; the size and settings as `rtcli.render` takes them."""
    from rtcli import api, wavefront
    from rtcli.render import sample_positions
    from rtcli.scene_api import Scene as Loaded
    from rtcli.scene_api import check_options
    from rtcli.writer import to_8bit
    check_options(width=width, height=height, samples=samples, max_depth=max_depth)
    if not isinstance(scene, Loaded):
        scene = api.load_scene(scene, width=width, height=height)
    model = scene.model
    w, h = _size(scene, width, height)
    for name, value, size in (("x", x, w), ("y", y, h)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise RtcliError(f"the pixel's {name} must be a whole number, got {value!r}")
    if not (0 <= x < w and 0 <= y < h):
        raise RtcliError(f"pixel ({x}, {y}) is outside the {w}x{h} image: x goes from 0 to {w - 1}, "
                         f"y from 0 to {h - 1}")
    settings = model.settings
    with settings.overridden(samples, max_depth):
        wavefront.prepare(model, bvh)
        n = settings.samples
        xs, ys = sample_positions(np.array([x]), np.array([y]), n)
        trees = [trace_one(model, float(xs[k, 0]), float(ys[k, 0]), w, h) for k in range(n * n)]
    value = np.array([t.value for t in trees]).reshape(n * n, 1, 3).mean(axis=0)     # as render_tile averages
    return Explanation(int(x), int(y), w, h, n, np.column_stack([xs[:, 0], ys[:, 0]]), trees, value[0],
                       to_8bit(value, gamma)[0], np.asarray(model.background, float), settings.specular, gamma)


def _size(scene, width, height) -> tuple[int, int]:
    from rtcli.scene_api import image_size
    w, h, _ = image_size(scene.model, width, height)
    return w, h


def _plain(value):
    """numpy and dataclasses as JSON's types."""
    if isinstance(value, RayNode | Hit | Feeler | LightSample | LightTerm | Glass):
        out = {k: _plain(v) for k, v in vars(value).items() if k != "terms"}
        if isinstance(value, RayNode) and value.hit is not None:
            out["local"] = _plain(value.local())
            out["total"] = _plain(value.total())
        if isinstance(value, Feeler):
            out["state"] = value.state
        return out
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


__all__ = ["explain", "Explanation", "RayNode", "Hit", "LightTerm", "LightSample", "Feeler", "Glass"]
