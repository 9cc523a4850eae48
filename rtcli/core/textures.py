"""Textures: a color T that modulates ambient and diffuse (notes 000 11.7.2).

For the kernels a material's texture is a row of floats (`texture_row`): its kind,
then a checker's 1/size and two colors, or an image's place in a texel array
(first texel, width, height) and whether it repeats. Texels are one (N, 3) array
of bytes, an image's rows one after another from its top row: 3 bytes a texel, so
a 10000 x 10000 picture takes 300 MB; each is read as byte / 255.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.kernels.variants import floor, kernel, maximum, minimum, select, to_int

NONE, CHECKER, IMAGE = 0, 1, 2                        # texture kinds
KIND, INV_SIZE, COLOR1, COLOR2, FIRST, WIDTH, HEIGHT, REPEAT = 0, 1, 2, 5, 8, 9, 10, 11
TEXTURE_WIDTH = 12


@dataclass(frozen=True)
class Checker:
    """POV-Ray's 3D checker in object space: c1 where floor(x/s)+floor(y/s)+floor(z/s) is even.

    Each coordinate is nudged by 1e-6 * size before the floor, so a surface lying
    on a cell boundary (a floor at y = 0) shows a clean pattern.
    """

    color1: np.ndarray
    color2: np.ndarray
    size: float = 1.0


@dataclass(frozen=True)
class ImageTexture:
    """A picture mapped by the shape's (u, v): (0, 0) is the image's bottom-left corner.

    Bilinear filtering between texel centres. With `repeat` the picture tiles the
    (u, v) plane; without it, (u, v) are clamped to the picture's edges. Texel
    values are used as stored (byte / 255), like every other color of the scene.
    """

    texels: np.ndarray      # (h, w, 3) uint8, row 0 at the top
    repeat: bool = True


def texture_row(texture, first: int = 0) -> np.ndarray:
    """The kernels' row for a texture (None: no texture); an image's texels start at `first`."""
    row = np.zeros(TEXTURE_WIDTH)
    if isinstance(texture, Checker):
        row[[KIND, INV_SIZE]] = CHECKER, 1 / texture.size
        row[COLOR1:COLOR1 + 3], row[COLOR2:COLOR2 + 3] = texture.color1, texture.color2
    elif isinstance(texture, ImageTexture):
        h, w, _ = texture.texels.shape
        row[[KIND, FIRST, WIDTH, HEIGHT, REPEAT]] = IMAGE, first, w, h, float(texture.repeat)
    return row


@kernel
def checker(tex, x, y, z):
    """The checker's color at the object-space point (x, y, z)."""
    s = tex[INV_SIZE]
    cells = floor(x * s + 1e-6) + floor(y * s + 1e-6) + floor(z * s + 1e-6)    # an integer, as a float
    even = cells % 2.0 == 0
    return (select(even, tex[COLOR1], tex[COLOR2]), select(even, tex[COLOR1 + 1], tex[COLOR2 + 1]),
            select(even, tex[COLOR1 + 2], tex[COLOR2 + 2]))


@kernel
def wrap(k, n, repeat):
    """A texel index: modulo n when the picture tiles, else clamped to 0 .. n - 1."""
    if repeat:
        return k % n
    return minimum(maximum(k, 0), n - 1)


@kernel
def bilinear(texels, top, bottom, xa, xb, fx, fy, channel):
    """One channel between four texels: columns xa, xb of the rows starting at `top`, `bottom`."""
    upper = texels[top + xa, channel] / 255.0 * (1 - fx) + texels[top + xb, channel] / 255.0 * fx
    lower = texels[bottom + xa, channel] / 255.0 * (1 - fx) + texels[bottom + xb, channel] / 255.0 * fx
    return upper * (1 - fy) + lower * fy


@kernel
def image(tex, texels, u, v):
    """The picture's color at (u, v), bilinear between texel centres."""
    first, w, h, repeat = to_int(tex[FIRST]), to_int(tex[WIDTH]), to_int(tex[HEIGHT]), tex[REPEAT] != 0
    if repeat:
        u, v = u - floor(u), v - floor(v)
    x = minimum(maximum(u, 0.0), 1.0) * w - 0.5          # continuous texel coordinates
    y = (1 - minimum(maximum(v, 0.0), 1.0)) * h - 0.5
    x0, y0 = floor(x), floor(y)
    fx, fy = x - x0, y - y0
    xa, xb = wrap(to_int(x0), w, repeat), wrap(to_int(x0) + 1, w, repeat)
    top, bottom = first + wrap(to_int(y0), h, repeat) * w, first + wrap(to_int(y0) + 1, h, repeat) * w
    return (bilinear(texels, top, bottom, xa, xb, fx, fy, 0), bilinear(texels, top, bottom, xa, xb, fx, fy, 1),
            bilinear(texels, top, bottom, xa, xb, fx, fy, 2))


@kernel
def texture_color(tex, texels, x, y, z, u, v):
    """T at a hit: 1 without a texture, the checker's color at the object-space point (x, y, z),
    or the picture's at the shape's (u, v)."""
    kind = tex[KIND]
    if kind == CHECKER:
        return checker(tex, x, y, z)
    if kind == IMAGE:
        return image(tex, texels, u, v)
    return 1.0, 1.0, 1.0
