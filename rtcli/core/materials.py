"""Materials: the coefficients of the shading equation, and a table of them by index.

`MaterialTable` gathers every material's coefficients into arrays, so shading all
hits is one vectorized expression indexed by each hit's material (and the compiled
engine reads the same arrays, one hit at a time).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rtcli.core.textures import ImageTexture, texture_row


def _rgb(x) -> np.ndarray:
    return np.broadcast_to(np.asarray(x, dtype=float), (3,)).copy()


@dataclass(frozen=True)
class Material:
    ambient: np.ndarray = field(default_factory=lambda: _rgb(0.8))      # ka (build: the diffuse color)
    diffuse: np.ndarray = field(default_factory=lambda: _rgb(0.8))      # kd
    specular: np.ndarray = field(default_factory=lambda: _rgb(0.0))     # ks
    shininess: float = 32.0                                             # n, the specular exponent
    emission: np.ndarray = field(default_factory=lambda: _rgb(0.0))     # added as is (002)
    reflection: np.ndarray = field(default_factory=lambda: _rgb(0.0))   # kr, weight of the mirror ray
    transmission: np.ndarray = field(default_factory=lambda: _rgb(0.0)) # kt, weight of the refracted ray
    ior: float = 1.0                                                    # index of refraction inside
    shadow: bool | str = True                                           # True full, False none, "filter"
    fresnel: bool = False                                               # kr, kt scale Fresnel's R, 1 - R
    texture: object = None                                              # Checker, ImageTexture or None
    name: str = ""                                                      # its name in `materials:`, if any


class MaterialTable:
    """Per-coefficient arrays, row k = material k; textures as rows over one texel array."""

    def __init__(self, materials: list[Material]):
        self.materials = list(materials)
        stack = lambda name: np.array([getattr(m, name) for m in materials], dtype=float)
        self.ka, self.kd, self.ks = stack("ambient"), stack("diffuse"), stack("specular")
        self.shininess, self.emission = stack("shininess"), stack("emission")
        self.kr, self.kt, self.ior = stack("reflection"), stack("transmission"), stack("ior")
        self.shadow = np.array([m.shadow is not False for m in materials], dtype=bool)   # stops or filters
        self.filters = np.array([m.shadow == "filter" for m in materials], dtype=bool)   # lets light through
        self.fresnel = np.array([m.fresnel for m in materials], dtype=np.int64)
        self.shiny = self.ks.max(axis=1) > 0            # which materials need the specular term,
        self.mirror = self.kr.max(axis=1) > 0           # a mirror ray,
        self.clear = self.kt.max(axis=1) > 0            # a refracted ray
        self.textured = [k for k, m in enumerate(materials) if m.texture is not None]
        self.texture, self.texels = _texture_rows(materials)

    def __len__(self) -> int:
        return len(self.materials)


def _texture_rows(materials) -> tuple[np.ndarray, np.ndarray]:
    """(M, 12) texture rows and the (N, 3) texels (uint8) of all image textures, one after
    another; one picture's own texels, not a copy, when the scene has only one."""
    rows, texels, first = [], [], 0
    for m in materials:
        rows.append(texture_row(m.texture, first))
        if isinstance(m.texture, ImageTexture):
            texels.append(np.ascontiguousarray(m.texture.texels, dtype=np.uint8).reshape(-1, 3))
            first += len(texels[-1])
    joined = texels[0] if len(texels) == 1 else np.concatenate(texels or [np.zeros((0, 3), np.uint8)])
    return np.array(rows).reshape(-1, 12), joined
