"""Images out: files written atomically, in the format their names ask for.

The format follows the output's extension (FORMATS: PNG, and JPEG, BMP, TIFF,
WebP, PPM for pictures; EXR and PFM for linear floats), so a .jpg name never
receives PNG bytes. 8-bit images go through Pillow; 16-bit PNG and TIFF through
deep.py, EXR through exr.py, PFM through pfm.py. An image may carry its provenance
(rendering/provenance.py: PNG text chunks, EXR header attributes, JSON in the TIFF,
JPEG and WebP description); the same pixels and provenance give the same bytes, so
two renders' files differ by their render time: compare pixels, not bytes.
Files are written to a temporary name in the target folder and renamed into
place, several outputs all or none, so a failed or interrupted run never leaves
a truncated image, nor one output without the other.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np
from PIL import Image
from PIL.PngImagePlugin import PngInfo

from rtcli.errors import RtcliError, quoted, shown
from rtcli.rendering import provenance
from rtcli.rendering.deep import write_png16, write_tiff16
from rtcli.rendering.exr import write_exr
from rtcli.rendering.pfm import write_pfm

# extension -> (Pillow format, save options); 16-bit id maps go to PNG only; EXR and PFM are rtcli's own
FORMATS = {
    ".png": ("PNG", {"compress_level": 3}),      # zlib's 6 takes twice as long for 13% fewer bytes
    ".jpg": ("JPEG", {"quality": 95}),
    ".jpeg": ("JPEG", {"quality": 95}),
    ".bmp": ("BMP", {}),
    ".tif": ("TIFF", {}),
    ".tiff": ("TIFF", {}),
    ".webp": ("WEBP", {"lossless": True}),
    ".ppm": ("PPM", {}),
    ".exr": ("EXR", {}),
    ".pfm": ("PFM", {}),
}
FLOATS = (".exr", ".pfm")                          # linear radiance as floats
DEEP = (".png", ".tif", ".tiff")                   # 16 bits a channel (--bit-depth 16)
ALPHA = (".png", ".tif", ".tiff", ".webp", ".exr")     # an alpha channel (render: {alpha: true})


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


def write_png(path: str, pixels: np.ndarray, meta: dict[str, str] | None = None) -> None:
    """Write one image atomically, in the format its extension names (see write_images)."""
    write_images([(path, pixels, meta)])


def write_images(items: list[tuple]) -> None:
    """Write each (path, pixels) or (path, pixels, provenance) in the format of its extension (see
    Staged.add for the pixels each takes), all or none: every image goes to a temporary file
    in its folder first, and only when all are written are they renamed into place; on any
    failure, or an interrupt, the temporary files and any image already renamed are removed."""
    with Staged() as staged:
        for path, pixels, *meta in items:
            staged.add(path, pixels, *meta)
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

    def add(self, path: str, pixels: np.ndarray, meta: dict[str, str] | None = None, layers: dict | None = None,
            half: bool = False) -> None:
        """Stage one image: uint8 (H, W, 3 or 4) in any format (4 channels: RGBA, in ALPHA's), uint16
        (H, W) as a 16-bit gray PNG (an id map), uint16 (H, W, 3 or 4) as a 16-bit PNG or TIFF,
        float (H, W, 3 or 4) linear colors with straight alpha as EXR (float16 with `half`, the views'
        data in `layers` as its layers) or PFM; `meta`, the provenance, where the format has room."""
        try:
            self.temps.append((_write_temp(path, pixels, meta, layers, half), path))
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


def _write_temp(path: str, pixels: np.ndarray, meta=None, layers=None, half: bool = False) -> str:
    """The image written to a new temporary file beside `path`; its name."""
    fmt, options = image_format(path, ids=pixels.dtype == np.uint16 and pixels.ndim == 2)
    _check_pixels(path, fmt, pixels)
    if fmt == "EXR":
        return write_temp(path, lambda f: write_exr(f, pixels, layers, meta, half))
    if fmt == "PFM":
        return write_temp(path, lambda f: write_pfm(f, pixels))
    if pixels.dtype == np.uint16 and pixels.ndim == 3:
        return write_temp(path, lambda f: (write_png16 if fmt == "PNG" else write_tiff16)(f, pixels, meta))
    img = Image.fromarray(pixels)                      # uint16 (H, W) -> I;16, uint8 (H, W, 3|4) -> RGB(A)
    options = {**options, **_meta_options(fmt, meta)} if meta else options
    return write_temp(path, lambda f: img.save(f, format=fmt, **options))


def _check_pixels(path: str, fmt: str, pixels: np.ndarray) -> None:
    """ValueError for pixels the format cannot take (the callers check what users ask for)."""
    ext = os.path.splitext(path)[1].lower()
    channels = pixels.shape[2] if pixels.ndim == 3 else 0
    fits = (pixels.dtype.kind == "f" and ext in FLOATS and channels in (3, 4) and (fmt == "EXR" or channels == 3)
            or pixels.dtype == np.uint16 and (channels == 0 or ext in DEEP and channels in (3, 4))
            or pixels.dtype == np.uint8 and ext not in FLOATS and (channels == 3 or channels == 4 and ext in ALPHA))
    if not fits:
        raise ValueError(f"cannot write {pixels.dtype} pixels of shape {pixels.shape} as {fmt}")


def _meta_options(fmt: str, meta: dict[str, str]) -> dict:
    """Pillow's save options that carry the provenance: PNG text chunks, or JSON as the TIFF's,
    JPEG's or WebP's image description (EXIF); BMP and PPM have no place for it."""
    if fmt == "PNG":
        info = PngInfo()
        for key, value in meta.items():
            info.add_text(key, value)
        return {"pnginfo": info}
    if fmt == "TIFF":
        return {"tiffinfo": {provenance.DESCRIPTION: provenance.as_json(meta),
                             provenance.SOFTWARE_TAG: provenance.software(meta)}}
    if fmt in ("JPEG", "WEBP"):
        exif = Image.Exif()
        exif[provenance.DESCRIPTION] = provenance.as_json(meta)
        exif[provenance.SOFTWARE_TAG] = provenance.software(meta)
        return {"exif": exif.tobytes()}
    return {}


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
