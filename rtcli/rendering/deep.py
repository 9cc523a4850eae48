"""16-bit images: PNG (RGB or RGBA, 16 bits a channel) and TIFF, written here with zlib.

Pillow writes 16-bit images in one channel only (its mode I;16), not RGB, so rtcli writes
these two formats itself, which are short: a PNG is its signature, an IHDR chunk, the text
chunks (the provenance, rendering/provenance.py), the rows (each behind filter byte 0, big
endian) compressed by zlib in IDAT chunks, and IEND (the PNG specification, 3rd edition); a
TIFF is a little-endian baseline file of one uncompressed strip, with its ImageDescription
(the provenance as JSON) and Software tags (TIFF 6.0). Any reader of 16-bit PNG or TIFF
reads them (pypng, OpenImageIO, GIMP, Pillow as 8 bits).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from rtcli.errors import RtcliError
from rtcli.rendering import provenance

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
IDAT_BYTES = 1 << 20                     # rows compressed into IDAT chunks of at most this size
COMPRESS_LEVEL = 3                       # as the 8-bit PNGs (rendering/writer.py)


def write_png16(f, pixels: np.ndarray, meta: dict[str, str] | None = None) -> None:
    """uint16 (H, W, 3) or (H, W, 4) as a 16-bit RGB or RGBA PNG, to the file object f."""
    h, w, channels = _check(pixels)
    f.write(PNG_SIGNATURE)
    f.write(_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 2 if channels == 3 else 6, 0, 0, 0)))
    for key, value in (meta or {}).items():
        f.write(_text_chunk(key, value))
    packer, pending = zlib.compressobj(COMPRESS_LEVEL), []
    rows = np.empty((h, 1 + w * channels * 2), dtype=np.uint8)
    rows[:, 0] = 0                                                   # filter type 0: the bytes as they are
    rows[:, 1:] = pixels.astype(">u2").reshape(h, -1).view(np.uint8)
    for y in range(0, h, 256):
        pending.append(packer.compress(rows[y:y + 256].tobytes()))
        if sum(map(len, pending)) >= IDAT_BYTES:
            f.write(_chunk(b"IDAT", b"".join(pending)))
            pending = []
    pending.append(packer.flush())
    f.write(_chunk(b"IDAT", b"".join(pending)))
    f.write(_chunk(b"IEND", b""))


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def _text_chunk(key: str, value: str) -> bytes:
    """tEXt when the value is Latin-1, else iTXt (UTF-8, uncompressed)."""
    name = key.encode("latin-1")[:79]
    try:
        return _chunk(b"tEXt", name + b"\0" + value.encode("latin-1"))
    except UnicodeEncodeError:
        return _chunk(b"iTXt", name + b"\0\0\0\0\0" + value.encode("utf-8"))


def write_tiff16(f, pixels: np.ndarray, meta: dict[str, str] | None = None) -> None:
    """uint16 (H, W, 3) or (H, W, 4) as a 16-bit RGB or RGBA TIFF (unassociated alpha), to f."""
    h, w, channels = _check(pixels)
    data = pixels.astype("<u2").tobytes()
    description = (provenance.as_json(meta).encode("ascii", "backslashreplace") if meta else b"") + b"\0"
    software = provenance.software(meta or {}).encode("ascii", "replace") + b"\0"
    bits_at = 8                                          # the header, then BitsPerSample's values, the texts, the pixels
    description_at = bits_at + 2 * channels
    software_at = description_at + len(description)
    pixels_at = software_at + len(software)
    ifd_at = pixels_at + len(data)
    ifd_at += ifd_at % 2                                 # an IFD starts on a word boundary
    if ifd_at > 0xFFFF_FF00:
        raise RtcliError(f"a 16-bit TIFF of {w}x{h} would pass the format's 4 GB; write a 16-bit PNG or an EXR")
    tags = [(256, 4, 1, w), (257, 4, 1, h), (258, 3, channels, bits_at), (259, 3, 1, 1), (262, 3, 1, 2),
            (270, 2, len(description), description_at), (273, 4, 1, pixels_at), (277, 3, 1, channels),
            (278, 4, 1, h), (279, 4, 1, len(data)), (284, 3, 1, 1), (305, 2, len(software), software_at)]
    if channels == 4:
        tags.append((338, 3, 1, 2))                      # ExtraSamples: unassociated alpha
    f.write(b"II*\0" + struct.pack("<I", ifd_at))
    f.write(struct.pack(f"<{channels}H", *([16] * channels)) + description + software + data)
    f.write(b"\0" * (ifd_at - pixels_at - len(data)))
    f.write(struct.pack("<H", len(tags)))
    for tag, kind, count, value in tags:
        inline = kind == 3 and count == 1
        f.write(struct.pack("<HHI", tag, kind, count) + (struct.pack("<HH", value, 0) if inline
                                                          else struct.pack("<I", value)))
    f.write(struct.pack("<I", 0))


def _check(pixels: np.ndarray) -> tuple[int, int, int]:
    if pixels.dtype != np.uint16 or pixels.ndim != 3 or pixels.shape[2] not in (3, 4):
        raise ValueError(f"a 16-bit image is uint16 (H, W, 3 or 4), not {pixels.dtype} {pixels.shape}")
    return pixels.shape
