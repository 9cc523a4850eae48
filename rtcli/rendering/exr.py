"""OpenEXR files: the linear radiance as float32 (or float16), alpha, the debug views as layers,
the provenance as header attributes; written and read through the OpenEXR package (the extra
`exr`: pip install -e '.[exr]'; README.md, Images).

The color is the channels R, G, B, with A when the render has alpha; as OpenEXR asks, color
with alpha is premultiplied (R, G, B are the straight color times A), so the background is 0
where A is 0. Each view (rtcli/inspect/views.py) is a layer whose channels are named as
Mitsuba 3's `aov` integrator names them for an AOV of the same name and type (LAYERS):
`normal.X` ... as `normal:sh_normal`, `depth.T` as `depth:depth`, `uv.U` as `uv:uv`,
`albedo.R` as `albedo:albedo`; pbrt-v4's GBufferFilm calls the normal and albedo `Ns.X` and
`Albedo.R`. The ids are a UINT channel (exact integers); everything else is float. Where the
pixel's ray misses: normal, uv and albedo 0, depth inf, bounces -1, ids 0.
"""

from __future__ import annotations

import numpy as np

from rtcli.errors import RtcliError, shown
from rtcli.rendering import provenance

LAYERS = {"normal": ("normal.X", "normal.Y", "normal.Z"), "depth": ("depth.T",), "uv": ("uv.U", "uv.V"),
          "albedo": ("albedo.R", "albedo.G", "albedo.B"), "bounces": ("bounces.Y",), "ids": ("ids.Y",)}
COLOR = ("R", "G", "B", "A")


def openexr():
    """The OpenEXR package, or the error that says how to install it. Imported when an EXR is
    written or read: it is an optional extra, and most commands never need it."""
    try:
        import OpenEXR  # an optional extra (exr), needed only by EXR files
    except ImportError:
        raise RtcliError("EXR files need the OpenEXR package: pip install -e '.[exr]' in the rtcli folder") \
            from None
    return OpenEXR


def write_exr(f, colors: np.ndarray, layers: dict | None = None, meta: dict[str, str] | None = None,
              half: bool = False) -> None:
    """Linear colors, float (H, W, 3) or (H, W, 4) with straight alpha, and the views' data
    (`layers`: kind -> array, as rtcli.view returns it), to the file object f."""
    exr = openexr()
    if colors.ndim != 3 or colors.shape[2] not in (3, 4) or colors.dtype.kind != "f":
        raise ValueError(f"an EXR's color is float (H, W, 3 or 4), not {colors.dtype} {colors.shape}")
    kind = np.float16 if half else np.float32
    alpha = colors[..., 3:] if colors.shape[2] == 4 else None
    rgb = colors[..., :3] * alpha if alpha is not None else colors
    channels = {name: np.ascontiguousarray(rgb[..., k], dtype=kind) for k, name in enumerate(COLOR[:3])}
    if alpha is not None:
        channels["A"] = np.ascontiguousarray(alpha[..., 0], dtype=kind)
    for name, data in (layers or {}).items():
        channels.update(layer_channels(name, np.asarray(data), kind))
    header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage, **(meta or {})}
    exr.File(header, channels).write(f)


def layer_channels(kind: str, data: np.ndarray, dtype) -> dict[str, np.ndarray]:
    """A view's data as its named channels: ids as uint32, the rest as `dtype`, misses as documented."""
    names = LAYERS[kind]
    if kind == "ids":
        return {names[0]: np.ascontiguousarray(data, dtype=np.uint32)}
    if kind == "uv":
        data = np.where(np.isfinite(data), data, 0.0)
    planes = data[..., None] if data.ndim == 2 else data
    return {name: np.ascontiguousarray(planes[..., k], dtype=dtype) for k, name in enumerate(names)}


def read_exr(path: str, max_pixels: int, header_only: bool = False) -> tuple[dict[str, np.ndarray], dict]:
    """An EXR's channels (name -> (H, W) array: float32, float16 or uint32) and its rtcli header
    attributes; RtcliError naming the file when it is not a readable EXR or has more than
    max_pixels. With header_only, no channel is read, and the second is the whole header."""
    exr = openexr()
    try:
        with exr.File(path, header_only=True) as head:
            header = dict(head.header())                 # the file's closing empties its header
        (x0, y0), (x1, y1) = header["dataWindow"]
        if (x1 - x0 + 1) * (y1 - y0 + 1) > max_pixels:
            raise RtcliError(f"{shown(path)}: {x1 - x0 + 1}x{y1 - y0 + 1} is more than the {max_pixels:,} pixels "
                             "rtcli reads")
        if header_only:
            return {}, header
        meta = provenance.ours(header.items())
        with exr.File(path, separate_channels=True) as image:
            return {name: np.array(c.pixels) for name, c in image.channels().items()}, meta
    except RtcliError:
        raise
    except Exception as error:                # the package raises plain exceptions for bad files
        reason = " ".join(str(error).split()) or type(error).__name__
        raise RtcliError(f"{shown(path)}: not a readable EXR: {reason}") from None


def color_of(channels: dict[str, np.ndarray], path: str) -> np.ndarray:
    """The color of an EXR's channels, float32 (H, W, 3), or (H, W, 4) with A (premultiplied, as
    stored)."""
    missing = [c for c in COLOR[:3] if c not in channels]
    if missing:
        raise RtcliError(f"{shown(path)}: an EXR without the color channels {', '.join(missing)}")
    names = COLOR if "A" in channels else COLOR[:3]
    return np.stack([channels[c].astype(np.float32) for c in names], axis=2)
