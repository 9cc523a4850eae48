"""A loaded Scene rendered: its image (rtcli.render, Scene.render), its signature's ids
(rtcli.signature) and the signature's legend. The command line is a thin layer over these and
gives the same bytes (docs/python-api.md)."""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rtcli.api.layers import check_layers, layers_of, meta_of, needs_floats
from rtcli.api.options import check_engine, check_options, described, image_size
from rtcli.api.results import ImageArray, RenderStats
from rtcli.errors import RtcliError, shown
from rtcli.rendering.outputs import check_format_options, check_outputs
from rtcli.rendering.tiles import TILE, Job
from rtcli.rendering.tiles import render as render_image

Progress = Callable[[int, int], None]          # (tiles done, tiles in all)


def render_scene(scene, *, width: int | None = None, height: int | None = None, samples: int | None = None,
           max_depth: int | None = None, engine: str = "auto", workers: int | None = None,
           block_size: int = 1, tile: int = TILE, gamma: bool = False, bvh: bool = True,
           linear: bool = False, alpha: bool | None = None, layers=(), bit_depth: int = 8, half: bool = False,
           output: str | os.PathLike | None = None, progress: Progress | None = None,
           notes: Callable[[str], None] | None = None) -> ImageArray:
    """Render a loaded Scene to an ImageArray: uint8 (H, W, 3), or with
    linear=True the float64 linear colors, unclamped.

    The options are the command line's: size (width or height alone keeps the aspect ratio),
    samples (n x n per pixel), max_depth, engine (auto, numpy or compiled), workers (processes;
    default all cores; the image is the same for any count), block_size (preview), tile, gamma
    (sRGB-encode the 8-bit image), bvh. `alpha` adds the alpha channel (default: the scene's
    `render: {alpha: ...}`); `layers`, view kinds, are computed too (image.layers) for an EXR.
    `output` also writes the image, after the same checks as `rtcli render -o` (made before
    rendering): an .exr or .pfm, or bit_depth=16 (PNG, TIFF), takes the linear colors, which the
    image then holds; `half` writes an EXR's floats as float16. `progress(done, total)` is called
    per tile; `notes(text)` receives remarks: a stretched camera (default: warnings.warn), and that
    the compiled code is being compiled, once, and how long it took (default: printed on stderr).
    """
    check_options(width=width, height=height, samples=samples, max_depth=max_depth, engine=engine,
                  workers=workers, block_size=block_size, tile=tile, gamma=gamma, bvh=bvh, linear=linear,
                  alpha=alpha, half=half, output=output, progress=progress, notes=notes)
    if linear and gamma:
        raise RtcliError("gamma encodes 8-bit images; a linear render is converted by image.to_8bit(gamma=True)")
    check_engine(engine)
    alpha, layers = scene.model.settings.alpha if alpha is None else alpha, check_layers(layers)
    w, h, note = image_size(scene.model, width, height)
    if note:
        (notes or _warn)(note)
    if output is not None:
        check_format_options(os.fspath(output), bit_depth=bit_depth, half=half, layers=layers, alpha=alpha,
                             gamma=gamma)
        _check_output(os.fspath(output), scene, False)
    floats = linear or needs_floats(output, bit_depth)
    job = Job(w, h, block_size, tile=tile, gamma=gamma and not floats, engine=engine, bvh=bvh, linear=floats,
              alpha=alpha)
    with scene.model.settings.overridden(samples, max_depth) as s:
        pixels, counts, seconds = _run(scene, job, workers, progress, notes)
        stats = RenderStats.of(w, h, s.samples, counts, seconds)
        meta = meta_of(scene, w, h, block_size=block_size, gamma=gamma, alpha=alpha, engine=stats.engine,
                       seconds=seconds)
        found = layers_of(scene, layers, w, h, tile, workers or os.cpu_count() or 1) if layers else {}
    image = ImageArray(pixels, stats, scene.inputs, meta=meta, layers=found)
    if output is not None:
        image.save(os.fspath(output), bit_depth=bit_depth, half=half, gamma=gamma)
    return image


def signature_scene(scene, *, width: int | None = None, height: int | None = None, block_size: int = 1,
              workers: int | None = None, output: str | os.PathLike | None = None) -> ImageArray:
    """The scene signature (notes 000 11.4) as an ImageArray of uint16 (H, W): per pixel the id of
    the first object hit, 0 for the background. It shows as the color-coded picture;
    `output` writes the ids as `rtcli signature --ids` does (a 16-bit PNG)."""
    check_options(width=width, height=height, block_size=block_size, workers=workers, output=output)
    check_ids(scene)
    if output is not None:
        _check_output(os.fspath(output), scene, True)
    w, h, _ = image_size(scene.model, width, height)
    ids, counts, seconds = _run(scene, Job(w, h, block_size, signature=True), workers, None, None)
    meta = meta_of(scene, w, h, block_size=block_size, content="ids", engine=counts.engine or "numpy",
                   seconds=seconds)
    image = ImageArray(ids, RenderStats.of(w, h, 1, counts, seconds), scene.inputs, meta=meta)
    if output is not None:
        image.save(os.fspath(output))
    return image


@dataclass(frozen=True)
class LegendRow:
    """One object of a signature: its id, name, shape and the pixels it covers."""

    id: int
    name: str
    shape: str
    pixels: int


def legend(scene, ids: np.ndarray) -> list[LegendRow]:
    """The rows of `rtcli signature --legend`: the background (id 0), then every object."""
    counts = np.bincount(_ids(ids, len(scene.model.objects)).ravel(), minlength=len(scene.model.objects) + 1)
    rows = [LegendRow(0, "(background)", "-", int(counts[0]))]
    return rows + [LegendRow(o.id, o.name, o.kind, int(counts[o.id])) for o in scene.model.objects]


def _ids(ids, objects: int) -> np.ndarray:
    """`ids` as an array of the scene's ids (0 .. objects); RtcliError otherwise."""
    array = np.asarray(ids) if isinstance(ids, np.ndarray) or isinstance(ids, (list, tuple)) else None
    if array is None or array.dtype.kind not in "iub":
        raise RtcliError(f"ids must be an array of object ids (rtcli.signature's), got {described(ids)}")
    if array.size and not 0 <= array.min() <= array.max() <= objects:
        raise RtcliError(f"ids holds {array.min() if array.min() < 0 else array.max()}, not an id of this scene "
                         f"(0 for the background, 1..{objects} its objects)")
    return array.astype(np.int64)


def check_ids(scene) -> None:
    """RtcliError when the scene has more objects than 16-bit signature ids can tell apart."""
    if len(scene.model.objects) > 65535:
        raise RtcliError(f"{shown(scene.source)}: {len(scene.model.objects)} objects, but signature ids are "
                         "16-bit (at most 65535 objects)")


def _warn(note: str) -> None:
    warnings.warn(note, stacklevel=3)                 # at the caller of render()


def _run(scene, job, workers: int | None, progress, notes):
    """The pixels, the counts, and the seconds of the render without the compiled code's start-up
    (counts.load_seconds)."""
    start = time.perf_counter()
    pixels, counts = render_image(scene.model, job, workers or os.cpu_count() or 1, progress, notes)
    return pixels, counts, time.perf_counter() - start - counts.load_seconds


def _check_output(path: str, scene, ids: bool) -> None:
    check_outputs([(path, ids)], list(scene.inputs))
