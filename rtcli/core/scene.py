"""The scene model: plain data built by rtcli/scenefile/, read by both engines. Picklable.

A scene may hold a million objects, so per object it keeps little: a slotted
SceneObject, its shape, and a row of the arrays below; or, for plain spheres, a row of
a SphereBlock's arrays (core/objects.py).
"""

from __future__ import annotations

import contextlib
import functools
from dataclasses import dataclass, field

import numpy as np

from rtcli.core.bvh import BVH, PAD
from rtcli.core.materials import MaterialTable
from rtcli.core.objects import SceneObject, singles, sphere_blocks
from rtcli.core.vec import length3

BVH_MIN_OBJECTS = 8        # from this many bounded objects on, a BVH over them pays (both engines)

class Boxes:
    """The objects' world-space boxes, padded like the BVH's nodes (core/bvh.py): boxes[k] is
    (lo, hi), or None for an unbounded object (a plane). Kept as two (N, 3) arrays."""

    def __init__(self, objects: list):
        n = len(objects)
        self.lo, self.hi = np.full((n, 3), np.nan), np.full((n, 3), np.nan)
        for k, o in singles(objects):
            box = o.bounds()
            if box is not None:
                self.lo[k], self.hi[k] = box
        for start, block in sphere_blocks(objects):
            self.lo[start:start + len(block)], self.hi[start:start + len(block)] = block.bounds()
        self.bounded = ~np.isnan(self.lo[:, 0])
        pad = PAD * np.maximum(np.abs(self.lo).max(axis=1), np.abs(self.hi).max(axis=1))
        pad = np.maximum(np.nan_to_num(pad), np.finfo(float).tiny)[:, None]
        self.lo, self.hi = self.lo - pad, self.hi + pad

    def __len__(self) -> int:
        return len(self.bounded)

    def __getitem__(self, k: int):
        return (self.lo[k], self.hi[k]) if self.bounded[k] else None

    def __iter__(self):
        return (self[k] for k in range(len(self)))


@dataclass
class Settings:
    width: int = 640                 # nc
    height: int = 480                # nr
    max_depth: int = 5               # rays per path, the primary included
    specular: str = "phong"          # phong: (R.V)^n, blinn: (N.H)^n
    samples: int = 1                 # n x n per pixel
    epsilon: float = 1e-6            # self-intersection offset, relative to the scene's size
    medium_ior: float = 1.0          # index of refraction around every object (the camera's medium)
    total_internal_reflection: str = "drop"   # drop: the refracted weight is lost; reflect: to the mirror ray
    alpha: bool = False              # the background transparent, in the images that have alpha
    shadow_terminator: str = "none"  # none: feelers leave from the hit; offset: Hanika's shift on smooth faces

    @contextlib.contextmanager
    def overridden(self, samples: int | None, max_depth: int | None):
        """These settings with samples and max_depth overridden (when given) for one render, then
        restored."""
        saved = self.samples, self.max_depth
        self.samples, self.max_depth = samples or saved[0], max_depth or saved[1]
        try:
            yield self
        finally:
            self.samples, self.max_depth = saved


@dataclass
class Scene:
    camera: object                   # callable (nc, nr) -> camera.Camera
    objects: list[SceneObject]
    materials: MaterialTable
    lights: list = field(default_factory=list)
    background: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ambient: np.ndarray = field(default_factory=lambda: np.full(3, 0.1))      # Ia
    settings: Settings = field(default_factory=Settings)
    eye: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel: object = None             # the numpy engine's rtcli.wavefront.accel.Accelerator, when built
    walks: object = None             # the numpy engine's compiled BVH walks (rtcli.compiled.walks.Walks), if given

    @functools.cached_property
    def boxes(self) -> Boxes:
        """Each object's world-space box (lo, hi), padded as the BVH's, or None when unbounded."""
        return Boxes(self.objects)

    @functools.cached_property
    def wants_bvh(self) -> bool:
        """Whether the scene has enough bounded objects for a BVH over them to pay. Both engines
        decide alike, so that ties between objects go the same way."""
        return int(self.boxes.bounded.sum()) >= BVH_MIN_OBJECTS

    @functools.cached_property
    def size(self) -> float:
        """A length for the scene's scale: the diagonal of its bounded objects and the eye."""
        b = self.boxes
        lo = np.min(np.vstack([self.eye, b.lo[b.bounded]]), axis=0)
        hi = np.max(np.vstack([self.eye, b.hi[b.bounded]]), axis=0)
        return max(float(length3(hi - lo)), 1e-3)

    @property
    def offset(self) -> float:
        """World-space distance a spawned ray starts off its surface."""
        return self.settings.epsilon * self.size

    @functools.cached_property
    def light_rows(self) -> np.ndarray:
        """(L, 22) the lights as the kernels read them (rtcli.core.lights)."""
        return np.array([light.row for light in self.lights]).reshape(-1, 22)


def object_tree(scene: Scene, levels=None) -> tuple[np.ndarray, BVH]:
    """(members, BVH): the scene's bounded objects and a BVH over their world boxes, as both
    engines walk it (`levels`: core/bvh_build.py)."""
    boxes = scene.boxes
    members = np.flatnonzero(boxes.bounded)
    return members, BVH(boxes.lo[members], boxes.hi[members], leaf_size=2, levels=levels)
