"""PFM, the Portable Float Map: linear RGB as float32, written and read here (no dependency).

The format is a text header, "PF" (three channels), the width and height, and a scale whose
sign gives the byte order (negative: little endian, which rtcli writes), then the rows of
float32 values from the bottom of the image to its top. It has no alpha and no place for
text, so a PFM carries no provenance (README.md, Images).
"""

from __future__ import annotations

import numpy as np

from rtcli.errors import RtcliError, shown

MAX_HEADER = 256


def write_pfm(f, colors: np.ndarray) -> None:
    """float (H, W, 3) as a little-endian RGB PFM, to the file object f."""
    if colors.ndim != 3 or colors.shape[2] != 3 or colors.dtype.kind != "f":
        raise ValueError(f"a PFM holds float (H, W, 3), not {colors.dtype} {colors.shape}")
    h, w = colors.shape[:2]
    f.write(f"PF\n{w} {h}\n-1.0\n".encode("ascii"))
    f.write(np.ascontiguousarray(colors[::-1], dtype="<f4").tobytes())


def read_pfm(path: str, max_pixels: int) -> np.ndarray:
    """A PFM's colors, float32 (H, W, 3) (or (H, W) for a one-channel "Pf" file), top row first.
    RtcliError naming the file when it is not a PFM, is cut short or has more than max_pixels."""
    with open(path, "rb") as f:
        head = f.read(MAX_HEADER)
        fields = head.split(maxsplit=4)
        try:
            kind, w, h, scale = fields[0], int(fields[1]), int(fields[2]), float(fields[3])
        except (IndexError, ValueError):
            raise RtcliError(f"{shown(path)}: not a PFM file (its header is not PF or Pf, width, height, scale)") \
                from None
        if kind not in (b"PF", b"Pf") or w < 1 or h < 1 or scale == 0:
            raise RtcliError(f"{shown(path)}: not a PFM file (its header is not PF or Pf, width, height, scale)")
        if w * h > max_pixels:
            raise RtcliError(f"{shown(path)}: {w}x{h} is {w * h:,} pixels, more than the {max_pixels:,} rtcli reads")
        start = _data_start(head)
        channels = 3 if kind == b"PF" else 1
        f.seek(start)
        data = f.read(w * h * channels * 4 + 1)
    if len(data) != w * h * channels * 4:
        raise RtcliError(f"{shown(path)}: a PFM of {w}x{h} should hold {w * h * channels * 4:,} bytes of pixels, "
                         f"not {len(data):,}")
    values = np.frombuffer(data, dtype="<f4" if scale < 0 else ">f4").reshape((h, w, channels)[:2 + (channels > 1)])
    return values[::-1].astype(np.float32)


def _data_start(head: bytes) -> int:
    """Where the pixels start: after the fourth whitespace-separated field and one whitespace byte."""
    k, fields = 0, 0
    while fields < 4:
        while k < len(head) and head[k:k + 1].isspace():
            k += 1
        while k < len(head) and not head[k:k + 1].isspace():
            k += 1
        fields += 1
    return k + 1
