"""Debug views as data: what the ray through each pixel's centre finds (rtcli.view, render --view;
the API's `view` in rtcli/api/__init__.py loads the scene and calls view_of).

The rays are traced by the numpy engine's own functions (intersect.find_first_hit,
intersect.surface, trace.trace), so a view shows exactly what the render sees. Views are
computed tile by tile in this process and returned as ImageArrays of data, whose `picture`
is how they show (in Jupyter, and the PNG that `rtcli render --view` writes; for ids, which
show as the signature's colors, the PNG is the 16-bit id map that `rtcli compare --ids` reads):

    normal   float64 (H, W, 3): the unit shading normal on the outside of the surface (the side
             its geometric normal points to), 0 on a miss; shown as (n + 1) / 2, so a face seen
             from behind, or with its normal flipped, has the opposite color of its neighbours
    depth    float64 (H, W): distance from the eye to the first hit; inf where the ray misses;
             shown as nearest / depth (white for the nearest, darker farther, black: a miss)
    uv       float64 (H, W, 2): the texture coordinates (u, v) of the first hit, NaN on a miss;
             shown as red = u, green = v (after their whole part is dropped), blue on a miss
    albedo   float64 (H, W, 3): the diffuse coefficient times the texture color, kd T; 0 on a miss
    bounces  int16 (H, W): how many times the pixel's deepest ray bounced (reflected or refracted
             rays in its longest path); -1 where the primary ray misses; shown from dark blue (0)
             to yellow (max_depth - 1), black on a miss
    ids      uint16 (H, W): the signature (rtcli.signature, which renders it in workers)
"""

from __future__ import annotations

import numpy as np

from rtcli.core.display import signature_colors, to_8bit
from rtcli.errors import plural
from rtcli.stats import Stats
from rtcli.wavefront.intersect import find_first_hit, surface, uv_at_hits
from rtcli.wavefront.rays import camera_rays
from rtcli.wavefront.trace import Log, trace

KINDS = ("normal", "depth", "uv", "albedo", "bounces", "ids")


class Deepest(Log):
    """A recorder (wavefront/trace.py) of the deepest ray each primary ray's tree reaches: depth[k]
    is raised to the depth of every ray descended from primary ray k (index[i]: the primary ray
    of the i-th ray at hand; at each depth a ray spawns at most one ray of each kind, so the
    indices of one batch are distinct)."""

    def __init__(self, depth: np.ndarray, index: np.ndarray):
        self.depth, self.index = depth, index

    def rays(self, rays, depth, hits) -> None:
        self.depth[self.index] = np.maximum(self.depth[self.index], depth)
        if depth == 1:
            self.missed = ~np.isfinite(hits.t)            # the primary rays that see the background

    def part(self, seen):
        return Deepest(self.depth, self.index[seen])

    def child(self, rows, kind, weights):
        return Deepest(self.depth, self.index[rows])


def view_of(model, kind: str, width: int, height: int, tile: int = 128) -> np.ndarray:
    """The data of view `kind` (KINDS but ids, which is the signature) of a scene model readied for
    the numpy engine, at width x height, computed tile by tile."""
    shape = {"depth": (height, width), "bounces": (height, width), "uv": (height, width, 2)}.get(
        kind, (height, width, 3))
    out = np.full(shape, _MISS[kind], dtype=np.int16 if kind == "bounces" else float)
    cam = model.camera(width, height)
    for top, left in ((top, left) for top in range(0, height, tile) for left in range(0, width, tile)):
        rows, cols = np.arange(top, min(top + tile, height)), np.arange(left, min(left + tile, width))
        jj, ii = (a.ravel() for a in np.meshgrid(rows, cols, indexing="ij"))
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            out[jj, ii] = _tile(model, kind, cam, ii, jj, width, height)
    return out


_MISS = {"normal": 0.0, "depth": np.inf, "uv": np.nan, "albedo": 0.0, "bounces": -1}


def _tile(model, kind: str, cam, ii, jj, w: int, h: int) -> np.ndarray:
    """The view's values at pixels (ii, jj): (n,) or (n, channels)."""
    rays = camera_rays(cam, ii + 0.5, jj + 0.5, w, h)
    if kind == "bounces":
        deepest = Deepest(np.zeros(len(rays), dtype=np.int64), np.arange(len(rays)))
        trace(model, rays, 1, Stats(), log=deepest)
        return np.where(deepest.missed, -1, deepest.depth - 1)
    hits = find_first_hit(model, rays)
    seen = np.flatnonzero(np.isfinite(hits.t))
    out = np.full((len(rays),) + {"depth": (), "uv": (2,)}.get(kind, (3,)), _MISS[kind])
    if kind == "depth":
        out[seen] = hits.t[seen] * np.linalg.norm(rays.d[:, seen], axis=0)
    elif kind == "uv":
        out[seen] = uv_at_hits(model, rays[seen], hits[seen]).T
    else:
        s = surface(model, rays[seen], hits[seen])
        out[seen] = (np.where(s.entering, s.n, -s.n) if kind == "normal"
                     else model.materials.kd[s.material].T * s.texture).T
    return out


def picture(data: np.ndarray, kind: str, max_depth: int = 5) -> np.ndarray:
    """How a view shows, 8-bit (H, W, 3) (see the module's docstring)."""
    data = np.asarray(data)
    if kind == "ids":
        return signature_colors(data)
    if kind == "normal":
        return to_8bit(np.where(np.any(data != 0, axis=2, keepdims=True), (data + 1) / 2, 0))
    if kind == "albedo":
        return to_8bit(data)
    if kind == "uv":
        seen = np.isfinite(data).all(axis=2, keepdims=True)
        rg = np.where(seen, data - np.floor(np.where(seen, data, 0)), 0)
        return to_8bit(np.concatenate([rg, np.where(seen, 0.0, 0.5)], axis=2))
    if kind == "bounces":
        ramp = np.array(RAMP, dtype=float) / 255
        t = np.clip(data, 0, None) / max(max_depth - 1, 1) * (len(ramp) - 1)
        k = np.minimum(t.astype(int), len(ramp) - 2)
        color = ramp[k] + (t - k)[..., None] * (ramp[k + 1] - ramp[k])
        return to_8bit(np.where((data < 0)[..., None], 0.0, color))
    finite = np.isfinite(data)
    near = data[finite].min() if finite.any() else 1.0
    gray = np.where(finite, near / np.where(finite, data, 1.0), 0)      # inverse depth: the nearest is white
    return to_8bit(np.repeat(gray[..., None], 3, axis=2))


RAMP = [(48, 18, 120), (33, 110, 160), (40, 170, 120), (170, 205, 50), (253, 231, 37)]   # dark blue to yellow


def summary(data: np.ndarray, kind: str, max_depth: int = 5) -> str:
    """One line on what a view's picture encodes, with the range of its values (for the command line)."""
    data = np.asarray(data)
    pixels = data.shape[0] * data.shape[1]
    if kind == "depth":
        finite = np.isfinite(data)
        if not finite.any():
            return f"depth: every ray misses ({plural(pixels, 'pixel')} black)"
        return (f"depth: {data[finite].min():.6g} (white) to {data[finite].max():.6g}, gray = nearest / depth; "
                f"{_missed(pixels - int(finite.sum()))} (black)")
    if kind == "bounces":
        hit = data >= 0
        top = int(data.max()) if hit.any() else 0
        return (f"bounces: 0 (dark blue) to {max_depth - 1} (yellow, max_depth {max_depth}); deepest here {top}; "
                f"{_missed(pixels - int(hit.sum()))} (black)")
    if kind == "uv":
        seen = np.isfinite(data).all(axis=2)
        if not seen.any():
            return f"uv: every ray misses ({plural(pixels, 'pixel')} blue)"
        u, v = data[seen].T
        return (f"uv: red = u, green = v (whole part dropped); u {u.min():.4g} to {u.max():.4g}, "
                f"v {v.min():.4g} to {v.max():.4g}; {_missed(pixels - int(seen.sum()))} (blue)")
    return {"normal": "normal: color = (n + 1) / 2 of the outward shading normal; black: a miss",
            "albedo": "albedo: kd T of the first hit; black: a miss",
            "ids": f"ids: the signature's ids, 0 (background) to {int(data.max(initial=0))}, as a 16-bit id map "
                   "(rtcli signature draws them in colors)"}[kind]


def _missed(n: int) -> str:
    return f"{plural(n, 'pixel')} {'misses' if n == 1 else 'miss'}"
