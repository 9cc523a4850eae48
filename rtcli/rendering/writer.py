"""Images out: files written atomically, in the format their names ask for.

The format follows the output's extension (FORMATS: PNG, and JPEG, BMP, TIFF,
WebP, PPM for pictures), so a .jpg name never receives PNG bytes. Files carry
no timestamp or other metadata, so the same pixels always give the same bytes.
Files are written to a temporary name in the target folder and renamed into
place, several outputs all or none, so a failed or interrupted run never leaves
a truncated image, nor one output without the other.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np
from PIL import Image

from rtcli.errors import RtcliError, quoted, shown

# extension -> (Pillow format, save options); 16-bit id maps go to PNG only
FORMATS = {
    ".png": ("PNG", {"compress_level": 3}),      # zlib's 6 takes twice as long for 13% fewer bytes
    ".jpg": ("JPEG", {"quality": 95}),
    ".jpeg": ("JPEG", {"quality": 95}),
    ".bmp": ("BMP", {}),
    ".tif": ("TIFF", {}),
    ".tiff": ("TIFF", {}),
    ".webp": ("WEBP", {"lossless": True}),
    ".ppm": ("PPM", {}),
}


def image_format(path: str, ids: bool = False) -> tuple[str, dict]:
    """(Pillow format, options) for an output's extension; RtcliError for an extension it is not."""
    ext = os.path.splitext(path)[1].lower()
    if ids and ext != ".png":
        raise RtcliError(f"{shown(path)}: an id map is written as a 16-bit PNG: the name must end in .png")
    if ext not in FORMATS:
        names = ", ".join(FORMATS)
        got = f"{quoted(ext)} is not one of" if ext else "no extension; use one of"
        raise RtcliError(f"{shown(path)}: the output format follows the extension: {got} {names}")
    return FORMATS[ext]


def write_png(path: str, pixels: np.ndarray) -> None:
    """Write one image atomically, in the format its extension names (see write_images)."""
    write_images([(path, pixels)])


def write_images(items: list[tuple[str, np.ndarray]]) -> None:
    """Write uint8 (H, W, 3) as RGB or uint16 (H, W) as 16-bit gray, each in the format of its
    extension, all or none: every image goes to a temporary file in its folder first, and
    only when all are written are they renamed into place; on any failure, or an
    interrupt, the temporary files and any image already renamed are removed."""
    with Staged() as staged:
        for path, pixels in items:
            staged.add(path, pixels)
        staged.commit()


class Staged:
    """Images written to temporary files one at a time and renamed into place together by
    commit(), all or none: a run that renders several images one after another holds
    only one in memory. Leaving the `with` block without commit() removes them all."""

    def __init__(self):
        self.temps: list[tuple[str, str]] = []     # (temporary file, final path)
        self.placed: list[str] = []

    def __enter__(self) -> "Staged":
        return self

    def add(self, path: str, pixels: np.ndarray) -> None:
        try:
            self.temps.append((_write_temp(path, pixels), path))
        except OSError as e:
            raise RtcliError(f"cannot write {shown(path)}: {e.strerror or e}") from None

    def commit(self) -> None:
        try:
            for tmp, path in self.temps:
                os.replace(tmp, path)
                self.placed.append(path)
        except OSError as e:
            raise RtcliError(f"cannot write {shown(self.temps[len(self.placed)][1])}: {e.strerror or e}") from None
        self.temps, self.placed = [], []               # in place: nothing left to undo

    def __exit__(self, kind, error, trace) -> None:
        for tmp, _ in self.temps:
            _remove(tmp)
        for path in self.placed:
            _remove(path)


def _write_temp(path: str, pixels: np.ndarray) -> str:
    """The image written to a new temporary file beside `path`; its name."""
    if not ((pixels.dtype == np.uint16 and pixels.ndim == 2)
            or (pixels.dtype == np.uint8 and pixels.ndim == 3 and pixels.shape[2] == 3)):
        raise ValueError(f"cannot write {pixels.dtype} pixels of shape {pixels.shape} as an image")
    fmt, options = image_format(path, ids=pixels.dtype == np.uint16)
    img = Image.fromarray(pixels)                      # uint16 (H, W) -> I;16, uint8 (H, W, 3) -> RGB
    return write_temp(path, lambda f: img.save(f, format=fmt, **options))


def write_temp(path: str, save) -> str:
    """A new temporary file beside `path`, filled by save(file object) and given the mode a plain
    open() would; its name. Nothing is left behind when save fails."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix=".rtcli-", suffix=os.path.splitext(path)[1], dir=folder)
    except OSError as e:
        raise RtcliError(f"cannot write {shown(path)}: {e.strerror}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            save(f)
        os.chmod(tmp, 0o666 & ~current_umask())               # as a plain open() would (mkstemp makes 0600)
    except BaseException:
        _remove(tmp)
        raise
    return tmp


def write_atomic(path: str, save) -> None:
    """Write a file by save(file object) into a temporary file beside `path`, then rename it into
    place: an interrupted or failed write leaves no partial file."""
    try:
        tmp = write_temp(path, save)
        try:
            os.replace(tmp, path)
        except BaseException:
            _remove(tmp)
            raise
    except OSError as e:
        raise RtcliError(f"cannot write {shown(path)}: {e.strerror or e}") from None


def _remove(path: str) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def current_umask() -> int:
    """The process's umask (read by setting it and back), for files made by mkstemp, which are 0600."""
    mask = os.umask(0)
    os.umask(mask)
    return mask
