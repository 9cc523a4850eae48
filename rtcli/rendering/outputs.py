"""Checks on output paths, made before any work: outputs never destroy anything.

An output must name a regular file or nothing yet, in a folder that exists, with
an extension the writer knows (writer.FORMATS); it must not be one of the run's
inputs (the scene, an include, a mesh, a texture, a compared image), compared by
real path and by inode so links and other spellings are caught; and two outputs
of one run must differ.
"""

from __future__ import annotations

import os
import stat

from rtcli.errors import RtcliError, shown
from rtcli.rendering.exr import LAYERS
from rtcli.rendering.movie import movie_format
from rtcli.rendering.writer import ALPHA, DEEP, FLOATS, image_format
from rtcli.scenefile.files import NUL, kind_of


def check_outputs(outputs: list[tuple[str, bool | str]], inputs: list[str]) -> None:
    """Refuse before rendering: `outputs` are (path, is an id map, or "movie" for an animated
    image), `inputs` the files read."""
    seen: dict = {}
    known = {_identity(p) for p in inputs} - {None}
    reals = {os.path.realpath(p) for p in inputs}
    for path, ids in outputs:
        _check_file(path, reals, known)
        real = os.path.realpath(path)
        if ids == "movie":
            movie_format(path)
        else:
            image_format(path, ids)
        if real in seen:
            raise RtcliError(f"{shown(path)}: given for two outputs; they must differ")
        seen[real] = path


def check_format_options(path: str, *, bit_depth: int = 8, half: bool = False, layers: tuple = (),
                         alpha: bool = False, gamma: bool = False) -> None:
    """RtcliError when the output's format cannot hold what is asked (README.md, Images): 16 bits
    a channel go to PNG or TIFF, float16 and layers to EXR, alpha to PNG, TIFF, WebP or EXR, and
    EXR and PFM hold linear radiance, never sRGB-encoded."""
    ext = os.path.splitext(path)[1].lower()
    unknown = [k for k in layers if k not in LAYERS]
    why = next((why for bad, why in [
        (bit_depth not in (8, 16), f"the bit depth is 8 or 16, not {bit_depth}"),
        (bit_depth == 16 and ext not in DEEP, "16 bits a channel go to .png or .tif (.exr and .pfm hold floats)"),
        (half and ext != ".exr", "float16 (--half) is for EXR: the name must end in .exr"),
        (unknown, f"no layer {', '.join(map(str, unknown))}: layers are {', '.join(LAYERS)}"),
        (layers and ext != ".exr", "layers go into a multi-layer EXR: the name must end in .exr"),
        (alpha and ext not in ALPHA, "alpha (render: {alpha: true} or --alpha) needs a format with an alpha "
                                     "channel: .png, .tif, .webp or .exr"),
        (gamma and ext in FLOATS, "EXR and PFM hold the linear radiance; --gamma encodes 8- and 16-bit images"),
    ] if bad), None)
    if why:
        raise RtcliError(f"{shown(path)}: {why}")


def check_file_output(path: str, inputs: list[str]) -> None:
    """The checks of check_outputs for an output that is not an image (a JUnit XML file)."""
    _check_file(path, {os.path.realpath(p) for p in inputs}, {_identity(p) for p in inputs} - {None})


def _check_file(path: str, reals: set, known: set) -> None:
    if "\0" in path:
        raise RtcliError(f"{shown(path)}: {NUL}")
    if os.path.realpath(path) in reals or _identity(path) in known:
        raise RtcliError(f"{shown(path)}: is an input of this run; it will not be overwritten "
                         "(choose another output name)")
    _check_replaceable(path)
    if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise RtcliError(f"{shown(path)}: output folder does not exist")


def _check_replaceable(path: str) -> None:
    """An existing output must be a regular file: a folder, FIFO or device is never replaced."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return
    except OSError as e:
        raise RtcliError(f"{shown(path)}: cannot use as output: {e.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        raise RtcliError(f"{shown(path)}: is {kind_of(st.st_mode)}, not a regular file; "
                         "it will not be replaced")


def _identity(path: str):
    """(device, inode) of an existing file, or None."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino
