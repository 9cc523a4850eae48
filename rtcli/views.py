"""Debug views as data: what the primary ray of each pixel hits (rtcli.view).

Each pixel's ray through its centre is traced to its first hit by the numpy engine's
own intersect.find_first_hit and intersect.surface, the functions the renderer shades
with, so a view shows exactly the surfaces the render sees. Views are computed tile
by tile in this process and returned as ImageArrays of data, which show in Jupyter
as pictures:

    depth    float64 (H, W): distance from the eye to the hit; inf where the ray misses
             (shown as nearest / depth: white for the nearest, darker farther)
    normal   float64 (H, W, 3): the unit shading normal, turned toward the eye; 0 on a miss
             (shown as (n + 1) / 2)
    albedo   float64 (H, W, 3): the diffuse coefficient times the texture color; 0 on a miss
    ids      uint16 (H, W): the signature (rtcli.signature, which renders it in workers)
"""

from __future__ import annotations

import numpy as np

from rtcli.errors import RtcliError
from rtcli.results import ImageArray
from rtcli.scene_api import Scene, Source

KINDS = ("depth", "normal", "albedo", "ids")


def view(scene: Scene | Source, kind: str, *, width: int | None = None, height: int | None = None,
         tile: int = 128) -> ImageArray:
    """The view `kind` (KINDS) of a Scene, or of what rtcli.load_scene takes, at its size or the one given."""
    from rtcli import api, wavefront
    from rtcli.render import camera_rays
    from rtcli.scene_api import check_options, image_size
    from rtcli.wavefront.intersect import find_first_hit, surface
    if kind not in KINDS:
        raise RtcliError(f"the view must be one of {', '.join(KINDS)}, got {kind!r}")
    scene = scene if isinstance(scene, Scene) else api.load_scene(scene)
    if kind == "ids":
        return api.signature(scene, width=width, height=height, workers=1)
    check_options(width=width, height=height, tile=tile)
    w, h, _ = image_size(scene.model, width, height)
    model = scene.model
    wavefront.prepare(model)
    out = np.full((h, w), np.inf) if kind == "depth" else np.zeros((h, w, 3))
    cam = model.camera(w, h)
    for top, left in ((top, left) for top in range(0, h, tile) for left in range(0, w, tile)):
        rows, cols = np.arange(top, min(top + tile, h)), np.arange(left, min(left + tile, w))
        jj, ii = (a.ravel() for a in np.meshgrid(rows, cols, indexing="ij"))
        rays = camera_rays(cam, ii + 0.5, jj + 0.5, w, h)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            hits = find_first_hit(model, rays)
            seen = np.flatnonzero(np.isfinite(hits.t))
            if kind == "depth":
                out[jj[seen], ii[seen]] = hits.t[seen] * np.linalg.norm(rays.d[:, seen], axis=0)
                continue
            s = surface(model, rays[seen], hits[seen])
            values = s.n if kind == "normal" else model.materials.kd[s.material].T * s.texture
            out[jj[seen], ii[seen]] = values.T
    return ImageArray(out, inputs=scene.inputs, picture=_picture(out, kind))


def _picture(data: np.ndarray, kind: str) -> np.ndarray:
    """How a view shows: depth as gray, nearest / depth; normals as (n + 1) / 2; albedo as colors."""
    from rtcli.writer import to_8bit
    if kind == "normal":
        return to_8bit(np.where(np.any(data != 0, axis=2, keepdims=True), (data + 1) / 2, 0))
    if kind == "albedo":
        return to_8bit(data)
    finite = np.isfinite(data)
    near = data[finite].min() if finite.any() else 1.0
    gray = np.where(finite, near / np.where(finite, data, 1.0), 0)      # inverse depth: the nearest is white
    return to_8bit(np.repeat(gray[..., None], 3, axis=2))
