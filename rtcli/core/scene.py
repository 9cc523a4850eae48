"""The scene model: plain data built by rtcli/scenefile/, read by both engines. Picklable."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from rtcli.core.bvh import padded
from rtcli.core.materials import MaterialTable
from rtcli.core.transform import Transform, outer_bounds

BVH_MIN_OBJECTS = 8        # from this many bounded objects on, a BVH over them pays (both engines)

@dataclass
class SceneObject:
    id: int                          # 1, 2, 3 ... in file order (signature ids)
    name: str
    shape: object                    # a shape of rtcli.shapes, in object space
    material: int                    # row of the scene's MaterialTable
    world_from_object: Transform | None = None     # None: object space is world space
    kind: str = ""                   # the YAML shape name, for legends

    @functools.cached_property
    def transform(self) -> np.ndarray | None:
        """The packed transform the kernels read (rtcli.core.transform), None without one."""
        return None if self.world_from_object is None else self.world_from_object.packed

    def bounds(self) -> tuple[np.ndarray, np.ndarray] | None:
        """World-space box, or None when unbounded."""
        return outer_bounds(self.world_from_object, self.shape.bounds())


@dataclass
class Settings:
    width: int = 640                 # nc
    height: int = 480                # nr
    max_depth: int = 5               # rays per path, the primary included
    specular: str = "phong"          # phong: (R.V)^n, blinn: (N.H)^n
    samples: int = 1                 # n x n per pixel
    epsilon: float = 1e-6            # self-intersection offset, relative to the scene's size


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

    @functools.cached_property
    def boxes(self) -> list:
        """Each object's world-space box (lo, hi), padded as the BVH's, or None when unbounded."""
        return [None if b is None else padded(*b) for b in (o.bounds() for o in self.objects)]

    @functools.cached_property
    def wants_bvh(self) -> bool:
        """Whether the scene has enough bounded objects for a BVH over them to pay. Both engines
        decide alike, so that ties between objects go the same way."""
        return sum(b is not None for b in self.boxes) >= BVH_MIN_OBJECTS

    @functools.cached_property
    def size(self) -> float:
        """A length for the scene's scale: the diagonal of its bounded objects and the eye."""
        boxes = [b for b in self.boxes if b is not None]
        lo = np.min([self.eye] + [b[0] for b in boxes], axis=0)
        hi = np.max([self.eye] + [b[1] for b in boxes], axis=0)
        return max(float(np.linalg.norm(hi - lo)), 1e-3)

    @property
    def offset(self) -> float:
        """World-space distance a spawned ray starts off its surface."""
        return self.settings.epsilon * self.size

    @functools.cached_property
    def light_rows(self) -> np.ndarray:
        """(L, 22) the lights as the kernels read them (rtcli.core.lights)."""
        return np.array([light.row for light in self.lights]).reshape(-1, 22)
