"""What the preview sends its pages over the websocket (docs/preview.md, How it works).

Pictures go as binary messages, a 16-byte header then the data, little-endian:

    u8 kind     1: a tile of colors, 2: the signature's id map
    u8 block    a tile's pass: each value stands for a block x block square of pixels (1 for ids)
    u16         0
    u32 render  the render it belongs to (a new one at every edit or frame)
    u16 x, y    the top-left pixel of the tile
    u16 cols, rows
    data        kind 1: rows x cols x 3 bytes, RGB; kind 2: rows x cols u16 object ids

A page draws a tile's cols x rows values as blocks of block x block pixels from (x, y),
clipped to the image. Everything else is a JSON object with a "type" (scene, progress, done,
error, compare, note).
"""

from __future__ import annotations

import struct

import numpy as np

TILE, IDS = 1, 2
HEADER = struct.Struct("<BBHIHHHH")


def tile_message(render: int, block: int, rows: np.ndarray, cols: np.ndarray, pixels: np.ndarray) -> bytes:
    """A tile of a pass: its grid points' 8-bit colors (len(rows), len(cols), 3)."""
    head = HEADER.pack(TILE, block, 0, render, int(cols[0]), int(rows[0]), len(cols), len(rows))
    return head + np.ascontiguousarray(pixels, dtype=np.uint8).tobytes()


def image_message(render: int, image: np.ndarray) -> bytes:
    """The whole picture as it is now, as one tile of block 1."""
    h, w = image.shape[:2]
    return HEADER.pack(TILE, 1, 0, render, 0, 0, w, h) + np.ascontiguousarray(image).tobytes()


def ids_message(render: int, ids: np.ndarray) -> bytes:
    """The signature's id map (H, W), for the page's hover and outline."""
    h, w = ids.shape
    return HEADER.pack(IDS, 1, 0, render, 0, 0, w, h) + np.ascontiguousarray(ids, dtype="<u2").tobytes()


def read(message: bytes) -> tuple[int, int, int, int, int, np.ndarray]:
    """(kind, block, render, x, y, data) of a binary message: data (rows, cols, 3) uint8 for a
    tile, (rows, cols) uint16 for ids. The page's reading of it, in Python (tests, tools)."""
    kind, block, _, render, x, y, cols, rows = HEADER.unpack_from(message)
    body = message[HEADER.size:]
    if kind == TILE:
        data = np.frombuffer(body, dtype=np.uint8).reshape(rows, cols, 3)
    else:
        data = np.frombuffer(body, dtype="<u2").reshape(rows, cols)
    return kind, block, render, x, y, data


def paint(image: np.ndarray, message: bytes) -> None:
    """Draw a tile message into `image` (H, W, 3) as a page does: each value over its block."""
    _, block, _, x, y, data = read(message)
    blocks = np.repeat(np.repeat(data, block, axis=0), block, axis=1)
    h, w = image.shape[:2]
    image[y:y + blocks.shape[0], x:x + blocks.shape[1]] = blocks[:h - y, :w - x]
