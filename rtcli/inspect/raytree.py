"""The ray tree of a pixel, as `rtcli explain` shows it (docs/debugging.md): each ray's hit, the
terms of the shading equation at it, its glass and its secondary rays, with the numbers the
render computed (explain.py records them).

A node's terms add up, in the engine's order, to its color:

    color = emission + ka Ia T + sum over light samples (diffuse + specular)
          + wr x reflected + wt x refracted                       (docs/scene-format.md, Shading)

`RayNode.total()` recomputes that sum from the terms shown, so a tree that hid a term would
not add up. The trees print as text (explain_text.py) and as JSON (`Explanation.json`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from rtcli.errors import RtcliError, one_line
from rtcli.inspect import explain_text

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
        return "\n".join(explain_text.node_lines(self, lambda text, role: text))

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
        chosen = range(len(self.trees)) if self._check(sample) is None else [sample]
        return {"pixel": [self.x, self.y], "image": [self.width, self.height],
                "samples_per_pixel": self.samples ** 2, "value": self.value, "byte": self.byte,
                "gamma": self.gamma,
                "samples": [{"sample": k, "position": self.positions[k], "ray": _plain(self.trees[k])}
                            for k in chosen]}

    def _check(self, sample):
        """`sample` (None for every one); RtcliError unless it is one of the pixel's samples."""
        n = len(self.trees)
        if sample is not None and (isinstance(sample, bool) or not isinstance(sample, int) or not 0 <= sample < n):
            raise RtcliError(f"sample must be None (every one) or an integer in 0..{n - 1}, got {one_line(repr(sample))[:60]}")
        return sample

    def json(self, sample: int | None = None) -> str:
        return json.dumps(_plain(self.to_dict(sample)), indent=2)

    def text(self, sample: int | None = 0, style=None) -> str:
        """The tree as text; `style(text, role)` may color it (roles: ray, miss, term, sum, note)."""
        self._check(sample)
        return explain_text.format_explanation(self, sample, style or (lambda text, role: text))

    def __str__(self) -> str:
        return self.text(None if len(self.trees) == 1 else 0)

    def __repr__(self) -> str:
        return (f"<rtcli Explanation of pixel ({self.x}, {self.y}) of {self.width}x{self.height} = {explain_text.vec(self.value)} "
                f"-> 8-bit {tuple(int(b) for b in self.byte)}; print() shows its tree>")

    def _repr_pretty_(self, p, cycle: bool) -> None:
        """IPython and Jupyter show the tree, as `rtcli explain` prints it (IPython's
        pretty-printing protocol), instead of the dataclass's fields."""
        p.text(str(self))


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

