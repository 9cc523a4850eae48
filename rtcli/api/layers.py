"""What an image carries besides its pixels: the views asked for as layers (an EXR holds them
beside the color; rendering/exr.py names their channels) and its provenance (the text every
image file holds; rendering/provenance.py)."""

from __future__ import annotations

import os

from rtcli.errors import RtcliError
from rtcli.inspect.views import KINDS, view_of
from rtcli.rendering import provenance
from rtcli.rendering.engine import numpy_engine
from rtcli.rendering.tiles import Job
from rtcli.rendering.tiles import render as render_image
from rtcli.rendering.writer import FLOATS


def check_layers(layers) -> tuple[str, ...]:
    """The layers as a tuple of view kinds, each once; RtcliError for one that is not a view."""
    layers = (layers,) if isinstance(layers, str) else tuple(layers or ())
    unknown = [k for k in layers if k not in KINDS]
    if unknown:
        raise RtcliError(f"no layer {', '.join(map(str, unknown))}: layers are {', '.join(KINDS)}")
    return tuple(dict.fromkeys(layers))


def layers_of(scene, kinds: tuple[str, ...], width: int, height: int, tile: int, workers: int) -> dict:
    """kind -> the view's data (rtcli.view's) at width x height: one ray through each pixel's centre.
    The ids are the signature's (traced in `workers` processes), the rest computed here."""
    found = {}
    for kind in kinds:
        if kind == "ids":
            found[kind] = render_image(scene.model, Job(width, height, signature=True), workers)[0]
        else:
            numpy_engine(scene.model)
            found[kind] = view_of(scene.model, kind, width, height, tile)
    return found


def meta_of(scene, width: int, height: int, *, block_size: int = 1, gamma: bool = False, alpha: bool = False,
            content: str = "color", engine: str = "none", seconds: float = 0.0) -> dict[str, str]:
    """The provenance of an image of a loaded Scene (api.scene.Scene), its settings as rendered."""
    s = scene.model.settings
    return provenance.provenance(scene.source, width, height, samples=s.samples, max_depth=s.max_depth,
                                 frame=scene.frame, block_size=block_size, gamma=gamma, alpha=alpha,
                                 content=content, engine=engine, seconds=seconds)


def needs_floats(output, bit_depth: int) -> bool:
    """Whether an output takes the linear colors: an EXR or PFM, or 16 bits a channel."""
    return output is not None and (os.path.splitext(os.fspath(output))[1].lower() in FLOATS or bit_depth == 16)
