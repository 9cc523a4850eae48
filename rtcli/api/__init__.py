"""rtcli as a library: load a scene, render it to a numpy array, a Pillow image or a file, look
inside it (its views, a pixel's ray tree).

    import rtcli
    scene = rtcli.load_scene("scenes/whitted.yaml", width=320)   # a path, YAML text or a dict
    image = rtcli.render(scene, samples=2)                       # uint8 (240, 320, 3); shows in Jupyter
    image.save("whitted.png"); image.to_pil(); image.stats

The command line is a thin layer over these functions and gives the same bytes
(docs/python-api.md). Bad input raises RtcliError with the message the command
line prints; a scene's errors are SceneErrors, located `file:line:col: key.path`
(a dict's by `<dict>: key.path`). The folder: loading.py (scenes loaded), scene.py (Scene),
options.py (the options' checks), pictures.py (a loaded Scene rendered), results.py
(ImageArray, RenderStats).
"""

from __future__ import annotations

import os
from collections.abc import Callable

from rtcli.api.loading import load
from rtcli.api.options import check_options, described, image_size
from rtcli.api.pictures import Progress, render_scene, signature_scene
from rtcli.api.results import ImageArray
from rtcli.api.scene import Scene, Source
from rtcli.errors import RtcliError
from rtcli.inspect.explain import Explanation, check_pixel, explain_pixel
from rtcli.inspect.views import KINDS, picture, view_of
from rtcli.rendering.engine import numpy_engine
from rtcli.rendering.tiles import TILE


def load_scene(source: Source, *, width: int | None = None, height: int | None = None, samples: int | None = None,
               max_depth: int | None = None, folder: str | os.PathLike | None = None,
               frame: int | None = None) -> Scene:
    """Read and check a scene: a path (str or os.PathLike), YAML text (a str with a line break, or
    a flow mapping `{...}`) or a dict of the same keys (docs/scene-format.md).

    width and height override the image size (one alone keeps the aspect ratio), samples and
    max_depth the render settings, as the command line's options do. Relative file names in
    YAML text or a dict are relative to `folder` (default: the current folder). `frame` picks
    the frame of an animated scene (default 1; `scene.at(k)` gives another).
    """
    check_options(width=width, height=height, samples=samples, max_depth=max_depth, frame=frame, folder=folder)
    scene = load(source, None if folder is None else os.fspath(folder), frame)
    return scene.override(width=width, height=height, samples=samples, max_depth=max_depth)


def _scene_of(scene: Scene | Source, frame: int | None) -> Scene:
    """A Scene as given (at `frame` when one is given), or loaded from what load_scene takes."""
    if isinstance(scene, Scene):
        return scene if frame is None else scene.at(frame)
    return load_scene(scene, frame=frame)


def render(scene: Scene | Source, *, width: int | None = None, height: int | None = None, samples: int | None = None,
           max_depth: int | None = None, engine: str = "auto", workers: int | None = None,
           block_size: int = 1, tile: int = TILE, gamma: bool = False, bvh: bool = True,
           linear: bool = False, alpha: bool | None = None, layers=(), bit_depth: int = 8, half: bool = False,
           output: str | os.PathLike | None = None, progress: Progress | None = None,
           notes: Callable[[str], None] | None = None, frame: int | None = None) -> ImageArray:
    """Render a Scene (or what load_scene takes) to an ImageArray: uint8 (H, W, 3), or with
    linear=True the float64 linear colors, unclamped. alpha, layers, bit_depth and half: see
    Scene.render (rtcli/api/pictures.py, render_scene) and docs/python-api.md.

    The options are the command line's: size (width or height alone keeps the aspect ratio),
    samples (n x n per pixel), max_depth, engine (auto, numpy or compiled), workers (processes;
    default all cores; the image is the same for any count), block_size (preview), tile, gamma
    (sRGB-encode the 8-bit image), bvh. `output` also writes the image, after the same checks
    as `rtcli render -o` (made before rendering). `progress(done, total)` is called per tile;
    `notes(text)` receives remarks: a stretched camera (default: warnings.warn), and that the
    compiled code is being compiled, once, and how long it took (default: printed on stderr).
    `frame` renders that frame of an animated scene (default: the Scene's own, frame 1 when
    loaded here).
    """
    check_options(frame=frame)
    return render_scene(_scene_of(scene, frame), width=width, height=height, samples=samples, max_depth=max_depth,
                        engine=engine, workers=workers, block_size=block_size, tile=tile, gamma=gamma, bvh=bvh,
                        linear=linear, alpha=alpha, layers=layers, bit_depth=bit_depth, half=half, output=output,
                        progress=progress, notes=notes)


def signature(scene: Scene | Source, *, width: int | None = None, height: int | None = None, block_size: int = 1,
              workers: int | None = None, output: str | os.PathLike | None = None,
              frame: int | None = None) -> ImageArray:
    """The scene signature (notes 000 11.4) as an ImageArray of uint16 (H, W): per pixel the id of
    the first object hit, 0 for the background. It shows as the color-coded picture;
    `output` writes the ids as `rtcli signature --ids` does (a 16-bit PNG). `frame` as for render."""
    check_options(frame=frame)
    return signature_scene(_scene_of(scene, frame), width=width, height=height, block_size=block_size,
                           workers=workers, output=output)


def view(scene: Scene | Source, kind: str, *, width: int | None = None, height: int | None = None,
         tile: int = 128) -> ImageArray:
    """The debug view `kind` (normal, depth, uv, albedo, bounces or ids; docs/debugging.md) of a
    Scene, or of what load_scene takes, at its size or the one given: an ImageArray of the view's
    data, which shows as its picture (rtcli/inspect/views.py)."""
    if not isinstance(kind, str) or kind not in KINDS:
        raise RtcliError(f"the view must be one of {', '.join(KINDS)}, got {described(kind)}")
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    if kind == "ids":
        return signature_scene(scene, width=width, height=height, workers=1)
    check_options(width=width, height=height, tile=tile)
    w, h, _ = image_size(scene.model, width, height)
    numpy_engine(scene.model)
    data = view_of(scene.model, kind, w, h, tile)
    return ImageArray(data, inputs=scene.inputs, picture=picture(data, kind, scene.model.settings.max_depth))


def explain(scene: Scene | Source, x: int, y: int, *, width: int | None = None, height: int | None = None,
            samples: int | None = None, max_depth: int | None = None, gamma: bool = False,
            bvh: bool = True) -> Explanation:
    """The ray trees of pixel (x, y) (column from the left, row from the top) of a Scene, or of
    what load_scene takes; the size and settings as render takes them (docs/debugging.md)."""
    check_options(width=width, height=height, samples=samples, max_depth=max_depth, gamma=gamma, bvh=bvh)
    if not isinstance(scene, Scene):
        scene = load_scene(scene, width=width, height=height)
    w, h, _ = image_size(scene.model, width, height)
    check_pixel(x, y, w, h)
    with scene.model.settings.overridden(samples, max_depth):
        numpy_engine(scene.model, bvh)
        return explain_pixel(scene.model, x, y, w, h, gamma)
