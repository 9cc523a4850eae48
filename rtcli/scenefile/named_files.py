"""The files a scene names: a mesh's OBJ file and a texture's picture (docs/scene-format.md, Values).

A relative name is relative to the folder of the file that names it (an include's,
not the scene's; for YAML text or a dict, load_scene's folder). Each file is read
within its size limit (files.py, limits.py), kept from one load to the next while a
watch runs when it did not change (reuse.py), and every error reading it is located
at the key that names it.
"""

from __future__ import annotations

import os

import numpy as np
from PIL import UnidentifiedImageError

from rtcli.errors import SOURCES, SceneError, shown
from rtcli.scenefile import reuse
from rtcli.scenefile.files import open_image
from rtcli.scenefile.limits import MAX_MESH_BYTES
from rtcli.scenefile.obj import read_obj
from rtcli.scenefile.params import Params


def load_texels(p: Params, key: str) -> np.ndarray:
    """The picture's texels (h, w, 3) as bytes, copied out of Pillow in bands of rows, so that
    loading holds Pillow's decoded image and one more byte array, not a float copy."""
    path = os.path.join(p.folder, p.string(key))
    try:
        with open_image(path) as img:
            rgb = img if img.mode == "RGB" else img.convert("RGB")
            w, h = rgb.size
            texels = np.empty((h, w, 3), dtype=np.uint8)
            band = max(1, (1 << 22) // max(w, 1))                     # about 12 MB a band
            for y in range(0, h, band):
                texels[y:y + band] = np.asarray(rgb.crop((0, y, w, min(h, y + band))))
            return texels
    except FileNotFoundError:
        raise not_found(p, key, path) from None
    except (UnidentifiedImageError, OSError) as e:
        raise p.error(key, f"cannot read image {shown(path)}: {e}") from None


def read_mesh_file(p: Params, key: str, path: str):
    """The OBJ data of the file at `path`, which the key `key` names."""
    try:
        return reuse.file_data(path, MAX_MESH_BYTES, lambda: read_obj(path))
    except FileNotFoundError:
        raise not_found(p, key, path) from None
    except OSError as e:
        raise p.error(key, f"cannot read {shown(path)}: {e.strerror or e}") from None


def not_found(p: Params, key: str, path: str) -> SceneError:
    """A mesh or texture file that is not there, with the folder it was looked for in and why
    there: a relative name is relative to the folder of the file that names it (an include's,
    not the scene's; for YAML text or a dict, load_scene's folder), and to no other."""
    if os.path.isabs(p.string(key)):
        return p.error(key, f"file not found: {shown(path)}")
    base = "load_scene's folder, the current one by default" if p.node.file in SOURCES else \
        "the folder of the file it is written in"
    looked = shown(os.path.abspath(os.path.dirname(path)))
    return p.error(key, f"file not found: {shown(path)} (looked for in {looked}: a relative name starts from {base})")
