"""What an image file says about itself, for `rtcli info` and `rtcli compare`: its format, size,
channels and provenance (rendering/provenance.py), read without decoding its pixels where
the format allows (EXR's header, Pillow's lazy open).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field

from PIL import Image

from rtcli.errors import RtcliError, shown
from rtcli.rendering import provenance
from rtcli.rendering.exr import COLOR, LAYERS, read_exr
from rtcli.scenefile.files import InputError, check_input

MAX_PIXELS = 40_000_000                 # per image, as rtcli compare (8K UHD is 33.2 million)


@dataclass(frozen=True)
class About:
    """An image file's format, size, channels (their names, or Pillow's mode) and provenance."""

    format: str
    width: int
    height: int
    channels: str
    meta: dict = field(default_factory=dict)


def about(path: str) -> About:
    """What the file at `path` says about itself; RtcliError naming it when it is not a readable image."""
    try:
        check_input(path, 1 << 40)
    except FileNotFoundError:
        raise RtcliError(f"{shown(path)}: no such file") from None
    except InputError as error:
        raise RtcliError(f"{shown(path)}: cannot read: {error}") from None
    ext = os.path.splitext(path)[1].lower()
    if ext == ".exr":
        return _about_exr(path)
    if ext == ".pfm":
        return _about_pfm(path)
    return _about_picture(path)


def _about_exr(path: str) -> About:
    _, header = read_exr(path, MAX_PIXELS, header_only=True)
    meta = provenance.ours(header.items())
    (x0, y0), (x1, y1) = header["dataWindow"]
    names = " ".join(sorted((c.name for c in header["channels"]), key=_channel_order))
    return About("EXR", int(x1 - x0 + 1), int(y1 - y0 + 1), names, meta)


ORDER = list(COLOR) + [c for names in LAYERS.values() for c in names]


def _channel_order(name: str) -> tuple:
    """The color first, then the layers as rtcli writes them, then any other channel."""
    return (ORDER.index(name), "") if name in ORDER else (len(ORDER), name)


def _about_pfm(path: str) -> About:
    with open(path, "rb") as f:
        fields = f.read(256).split(maxsplit=4)
    try:
        kind, w, h = fields[0], int(fields[1]), int(fields[2])
    except (IndexError, ValueError):
        raise RtcliError(f"{shown(path)}: not a PFM file") from None
    if kind not in (b"PF", b"Pf"):
        raise RtcliError(f"{shown(path)}: not a PFM file")
    return About("PFM", w, h, "R G B" if kind == b"PF" else "Y")


def _about_picture(path: str) -> About:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with Image.open(path) as img:
                return About(img.format or "?", img.size[0], img.size[1], _mode(img, path), picture_meta(img))
    except (OSError, ValueError, SyntaxError, EOFError) as error:
        reason = " ".join(str(error).split()) or type(error).__name__
        raise RtcliError(f"{shown(path)}: not a readable image: {reason}") from None


def _mode(img, path: str) -> str:
    """Pillow's mode, with the bits a channel of a PNG or TIFF of 16 (which Pillow reads as 8)."""
    bits = 16 if img.mode.startswith("I;16") else 8
    if img.format == "PNG":
        with open(path, "rb") as f:
            bits = f.read(25)[24]                       # IHDR's bit depth (Pillow opened it: it is there)
    elif img.format == "TIFF":
        bits = max(img.tag_v2.get(258, (8,)) or (8,))
    return f"{img.mode}, {bits}-bit" if bits != 8 else img.mode


def picture_meta(img) -> dict[str, str]:
    """The provenance of an image Pillow opened: PNG (and APNG) text chunks, or the JSON of the TIFF's,
    JPEG's or WebP's image description or of a GIF's comment; {} when it has none."""
    if img.format == "PNG":
        return provenance.ours(getattr(img, "text", {}).items())
    if img.format == "TIFF":
        return provenance.from_json(img.tag_v2.get(provenance.DESCRIPTION))
    if img.format == "GIF":
        return provenance.from_json(img.info.get("comment"))
    return provenance.from_json(img.getexif().get(provenance.DESCRIPTION))
