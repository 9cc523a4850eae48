"""What the Python API returns: images that are numpy arrays, and the statistics of a render.

An ImageArray is a numpy array (anything that takes an array takes it) that also
shows itself inline in Jupyter (`_repr_png_`), converts to a Pillow image and saves
through the command line's writer, with its output checks (docs/python-api.md).
Three kinds come out of rtcli.render and rtcli.signature:

    uint8 (H, W, 3)     the image as `rtcli render` writes it
    float64 (H, W, 3)   the linear colors traced (render(..., linear=True)): unclamped,
                        to_8bit() of them is the 8-bit image, exactly
    uint16 (H, W)       signature ids: 0 for the background, else the object's id

With alpha (render(..., alpha=True), or the scene's `render: {alpha: true}`) an image has a
fourth channel, the share of each pixel's samples that hit an object, and its colors are
straight (not multiplied by it). An image also carries its provenance (`meta`, the text its
files hold, rendering/provenance.py) and the views asked for as layers (`layers`: kind ->
data, which an EXR holds beside the color).
"""

from __future__ import annotations

import io
import os
from dataclasses import asdict, dataclass

import numpy as np
from PIL import Image

from rtcli.api.options import check_options, check_path
from rtcli.core.display import signature_colors, to_8bit, to_8bit_alpha, to_16bit
from rtcli.errors import RtcliError, shown
from rtcli.rendering.outputs import check_format_options, check_outputs
from rtcli.rendering.writer import FLOATS, Staged


@dataclass(frozen=True)
class RenderStats:
    """Rays traced by kind, the engine that traced them, and how long it took."""

    width: int                       # the image rendered, in pixels
    height: int
    samples: int                     # n x n per pixel
    engine: str                      # "numpy" or "compiled"
    primary: int                     # rays by kind
    shadow: int
    reflected: int
    refracted: int
    seconds: float                   # wall time of the render (tiles traced and assembled), start-up apart
    load_seconds: float = 0.0        # the compiled code's start-up: numba imported, machine code loaded or compiled
    compile_seconds: float = 0.0     # of which compiling (0 when the code came from numba's cache)

    @classmethod
    def of(cls, width: int, height: int, samples: int, counts, seconds: float,
           start_up: bool = True) -> "RenderStats":
        """The stats of a render of width x height at samples x samples from its counts (a
        rtcli.stats.Stats: rays by kind, the engine, its start-up unless `start_up` is False)."""
        load = (counts.load_seconds, counts.compile_seconds) if start_up else (0.0, 0.0)
        return cls(width, height, samples, counts.engine or "none", counts.primary, counts.shadow, counts.reflected,
                   counts.refracted, seconds, *load)

    @property
    def total(self) -> int:
        return self.primary + self.shadow + self.reflected + self.refracted

    @property
    def rays_per_second(self) -> float:
        return self.total / max(self.seconds, 1e-9)

    def as_dict(self) -> dict:
        """The fields, total and rays_per_second: what `rtcli render --stats --json` prints."""
        return {**asdict(self), **{k: round(getattr(self, k), 6) for k in ("seconds", "load_seconds",
                                                                           "compile_seconds")},
                "total": self.total, "rays_per_second": round(self.rays_per_second)}

    def line(self, seconds: float | None = None) -> str:
        """The one line of `rtcli render --stats` (over `seconds`, when another span is meant, from
        which the start-up is taken out), then the compiled code's start-up, when there was one."""
        s = self.seconds if seconds is None else max(seconds - self.load_seconds, 0.0)
        start = ""
        if self.compile_seconds:
            start = f"; {self.load_seconds:.2f} s more to compile the engine (once: it is cached)"
        elif self.load_seconds:
            start = f"; {self.load_seconds:.2f} s more to load the compiled code"
        return (f"rays: {self.primary} primary, {self.shadow} shadow, {self.reflected} reflected, "
                f"{self.refracted} refracted, {self.total} total; {self.engine} engine; {s:.2f} s; "
                f"{self.total / max(s, 1e-9):,.0f} rays/s{start}")


class ImageArray(np.ndarray):
    """A rendered image or id map: a numpy array that shows itself in Jupyter and saves itself.

    `stats` is the RenderStats of the render that made it (None on arrays derived from it);
    `inputs` the files the scene read, which save() refuses to overwrite; `picture` how a
    debug view (rtcli.view) shows, 8-bit (None for images, which show as themselves).
    """

    stats: RenderStats | None
    inputs: tuple[str, ...]
    picture: np.ndarray | None
    meta: dict
    layers: dict

    def __new__(cls, pixels, stats: RenderStats | None = None, inputs=(), picture=None, meta=None,
                layers=None) -> ImageArray:
        image = np.asarray(pixels).view(cls)
        image.stats, image.inputs, image.picture = stats, tuple(inputs), picture
        image.meta, image.layers = dict(meta or {}), dict(layers or {})
        return image

    def __array_finalize__(self, obj) -> None:
        self.stats, self.inputs, self.picture = None, getattr(obj, "inputs", ()), None
        self.meta, self.layers = {}, {}                  # an array derived from an image is not that image

    @property
    def is_ids(self) -> bool:
        """Whether this is a signature id map (uint16 (H, W))."""
        return self.ndim == 2 and self.dtype == np.uint16

    def to_8bit(self, gamma: bool = False) -> ImageArray:
        """The 8-bit image: linear colors clamped to [0, 1], optionally sRGB-encoded, rounded; an id
        map as its signature picture (a fixed color per id, as `rtcli signature` draws it); a
        debug view as its picture."""
        check_options(gamma=gamma)
        if self.picture is not None:
            return ImageArray(self.picture, inputs=self.inputs)
        if self.is_ids:
            return ImageArray(signature_colors(np.asarray(self)), inputs=self.inputs)
        if self.ndim != 3 or self.shape[2] not in (3, 4):
            raise RtcliError(f"not an image: an array of shape {self.shape}")
        if self.dtype == np.uint8:
            return self
        convert = to_8bit_alpha if self.shape[2] == 4 else to_8bit
        return ImageArray(convert(np.asarray(self, dtype=float), gamma), inputs=self.inputs, meta=self.meta)

    def to_pil(self):
        """A Pillow image: RGB (RGBA) for colors (linear ones converted by to_8bit()), 16-bit gray for ids."""
        return Image.fromarray(np.asarray(self if self.is_ids else self.to_8bit()))

    def save(self, path: str, *, bit_depth: int = 8, half: bool = False, gamma: bool = False) -> None:
        """Write the image as `rtcli render` (or an id map as `rtcli signature --ids`) would: the format
        follows the extension, the file is replaced atomically, and an input of the scene, a
        folder or a device is refused (RtcliError). Linear colors go to .exr and .pfm as floats
        (EXR: float16 with `half`, and the layers), with bit_depth=16 to a 16-bit PNG or TIFF,
        else to 8 bits; `gamma` sRGB-encodes linear colors on their way to 8 or 16 bits."""
        path = check_path("path", path)
        check_outputs([(path, self.is_ids)], list(self.inputs))
        with Staged() as staged:
            self.stage(staged, path, bit_depth=bit_depth, half=half, gamma=gamma)
            staged.commit()

    def stage(self, staged: Staged, path: str, *, bit_depth: int = 8, half: bool = False, gamma: bool = False) -> None:
        """Write the image to a temporary file of `staged` (rendering/writer.Staged), as save() says."""
        check_format_options(path, bit_depth=bit_depth, half=half, layers=tuple(self.layers), gamma=gamma,
                             alpha=self.ndim == 3 and self.shape[2] == 4 and self.picture is None)
        meta = self.meta
        if gamma and self.dtype.kind == "f" and os.path.splitext(path)[1].lower() not in FLOATS and meta:
            meta = {**meta, "rtcli.gamma": "true"}               # encoded on the way to the file
        staged.add(path, self._file_pixels(path, bit_depth, gamma), meta, self.layers, half)

    def _file_pixels(self, path: str, bit_depth: int, gamma: bool) -> np.ndarray:
        if self.is_ids:
            return np.asarray(self)
        floats = os.path.splitext(path)[1].lower() in FLOATS
        if floats or bit_depth == 16:
            if self.dtype.kind != "f" or self.picture is not None:
                raise RtcliError(f"{shown(path)}: {'EXR and PFM hold' if floats else '16-bit images take'} the "
                                 "linear colors: render with linear=True")
            return np.asarray(self, dtype=np.float64) if floats else to_16bit(np.asarray(self, dtype=float), gamma)
        return np.asarray(self.to_8bit(gamma))

    def _repr_png_(self) -> bytes | None:
        """PNG bytes for Jupyter: the 8-bit image, or the signature picture of ids; None (plain text)
        for an array that is neither."""
        if not (self.picture is not None or self.is_ids
                or (self.ndim == 3 and self.shape[2] in (3, 4) and self.dtype.kind in "uf")):
            return None
        return png_bytes(np.asarray(self.to_8bit()))


def png_bytes(pixels: np.ndarray) -> bytes:
    """An 8-bit image encoded as PNG, in memory."""
    buffer = io.BytesIO()
    Image.fromarray(pixels).save(buffer, format="PNG")
    return buffer.getvalue()
