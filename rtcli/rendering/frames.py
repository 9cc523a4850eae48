"""Rendering an animation's frames (README.md, Animation).

`rtcli render` comes here for a sequence of frames to image files (`-o out/frame_%04d.png`,
the frame number in printf's %d form) or to a movie (`-o movie.apng`, `--movie`).
Frames are rendered one after another, each on every core (or a frame a task on a
cluster, rtcli/cluster/renders.py), and each file is
written, atomically, as soon as its frame is done: an interrupted run keeps the frames
it finished, and `--skip-existing` renders only the frames whose files are missing.
Every frame is checked (built) before the first is rendered, so an error in any of
them stops the run before it writes anything.
"""

from __future__ import annotations

import contextlib
import os
import re
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from PIL import Image, UnidentifiedImageError

from rtcli.errors import RtcliError, shown
from rtcli.rendering.movie import check_rate, check_size, is_movie, movie_format, write_movie
from rtcli.rendering.provenance import provenance
from rtcli.rendering.tiles import render as render_tiles
from rtcli.rendering.writer import write_png
from rtcli.scenefile.animation import Animation
from rtcli.stats import Stats

PATTERN = re.compile(r"(?:[^%]|%%)*%0?(?:[1-9]\d?)?d(?:[^%]|%%)*", re.DOTALL)  # one %d, %04d ... (width < 100)


def _frames_of(animation: Animation, scene_file: str) -> str:
    n = animation.frames
    return f"{shown(scene_file)} is a still (one frame)" if animation.still else \
        f"{shown(scene_file)} has {n} frames (1-{n})"


def overrides(samples: int | None, max_depth: int | None) -> dict:
    """The render settings the command line changes."""
    return {name: v for name, v in (("samples", samples), ("max_depth", max_depth)) if v}


def apply(scene, changes: dict):
    for name, value in changes.items():
        setattr(scene.settings, name, value)
    return scene


# --- sequences ---
def wants_sequence(output: str | None, frames: str | None, movie: str | None) -> bool:
    """Whether the command writes a sequence of frames (files or a movie) rather than one image."""
    return bool(frames or movie or is_movie(output) or (output and "%" in output))


@dataclass
class Sequence:
    """Which frames to render, the file of each (none when only movies are written), the movies."""

    frames: list[int]
    paths: dict = field(default_factory=dict)
    movies: list = field(default_factory=list)


def sequence(animation: Animation, scene_file: str, output: str | None, frames: str | None,
             frame: int | None, movie: str | None) -> Sequence:
    """The frames and files a command asks for (README.md, Animation)."""
    if frames and frame:
        raise RtcliError("--frames and --frame: give one")
    if movie:
        movie_format(movie)
    for name in (m for m in (output, movie) if is_movie(m) and PATTERN.fullmatch(m)):
        raise RtcliError(f"-o {shown(name)}: a movie is one file, so its name takes no frame number; "
                         "for one image a frame, name them .png (frame_%04d.png)")
    wanted = [frame] if frame else _range(frames, animation, scene_file)
    movies = [m for m in (output if is_movie(output) else None, movie) if m]
    for m in movies:
        check_rate(m, len(wanted), animation.clock.fps)
    if output and not is_movie(output):
        if "%" in output:
            if not PATTERN.fullmatch(output):
                raise RtcliError(f"-o {shown(output)}: a frame pattern has one %d (or %04d ..., a width below "
                                 "100) for the frame number, and %% for a percent sign")
            return Sequence(wanted, {k: output % k for k in wanted}, movies)
        if len(wanted) > 1:
            raise RtcliError(f"-o {shown(output)}: {len(wanted)} frames need a name with the frame number "
                             "(frame_%04d.png) or a movie (.apng, .gif)")
        return Sequence(wanted, {wanted[0]: output}, movies)
    if movies:
        return Sequence(wanted, {}, movies)
    name = os.path.splitext(os.path.basename(scene_file))[0]
    return Sequence(wanted, {k: f"{name}_{k:04d}.png" for k in wanted}, movies)


def _range(text: str | None, animation: Animation, scene_file: str) -> list[int]:
    n = animation.frames
    if not text:
        return list(range(1, n + 1))
    m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", text)
    first, last = (int(m.group(1)), int(m.group(2) or m.group(1))) if m else (0, 0)
    if not m or first < 1 or last < first:
        raise RtcliError(f"--frames {shown(text)}: give a range FIRST-LAST of frame numbers, from 1 (e.g. 1-{n})")
    if last > n:
        raise RtcliError(f"--frames {shown(text)}: {_frames_of(animation, scene_file)}")
    return list(range(first, last + 1))


def to_render(seq: Sequence, skip_existing: bool, job) -> list[int]:
    """The sequence's frames to render: all, or with `skip_existing` those without a file that is
    an image of the job's size (one of another size is rendered again)."""
    return [k for k in seq.frames
            if not (skip_existing and k in seq.paths and has_image(seq.paths[k], job.width, job.height))]


def has_image(path: str, width: int, height: int) -> bool:
    """Whether `path` is a regular file holding an image of width x height (only its header is read):
    what --skip-existing keeps."""
    if not os.path.isfile(path):
        return False
    try:
        with _frame_file(path, width, height) as img:
            return img.size == (width, height)
    except (OSError, UnidentifiedImageError, ValueError, Image.DecompressionBombError):
        return False


@contextlib.contextmanager
def _frame_file(path: str, width: int, height: int):
    """An earlier frame opened by Pillow (its header read): one that says it holds more pixels
    than width x height is a DecompressionBombError before anything is decoded, never
    Pillow's warning."""
    threshold = Image.MAX_IMAGE_PIXELS
    Image.MAX_IMAGE_PIXELS = (width * height + 1) // 2          # Pillow refuses above twice this
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as img:
                yield img
    finally:
        Image.MAX_IMAGE_PIXELS = threshold


def render_sequence(loaded, seq: Sequence, job, skip_existing: bool, frames: Callable) -> Stats:
    """Render the sequence's frames, writing each file as its frame is done and the movies at the
    end; frames whose files exist are skipped with `skip_existing` (read back for a movie).
    `frames(todo)` yields (frame, image, stats) for the frames to do: local_frames here, or a
    cluster's (rtcli/cluster/renders.py). `loaded` is the scene file (api.loading.Loaded)."""
    todo = to_render(seq, skip_existing, job)
    if seq.movies:
        check_size(len(seq.frames), job.width, job.height)
    for k in todo:
        if k != loaded.frame:
            loaded.animation.scene(k)                          # every frame checked before any is rendered
    movie = {k: _read_back(seq.paths[k], job) for k in seq.frames if k not in todo and seq.movies}
    stats, start, total = Stats(), time.perf_counter(), 0.0
    for k, image, s in frames(todo) if todo else ():
        seconds = time.perf_counter() - start
        total += seconds
        if k in seq.paths:
            write_png(seq.paths[k], image, frame_meta(loaded, job, k, s.engine, seconds))
        if seq.movies:
            movie[k] = image
        stats.add(s)
        stats.engine = s.engine
        start = time.perf_counter()
    frame_range = f"{seq.frames[0]}-{seq.frames[-1]}" if seq.frames else "-"
    for path in seq.movies:
        write_movie(path, [movie[k] for k in seq.frames], loaded.animation.clock.fps,
                    frame_meta(loaded, job, frame_range, stats.engine, total))
    return stats


def frame_meta(loaded, job, frame, engine: str, seconds: float) -> dict[str, str]:
    """The provenance of frame `frame`'s image (rendering/provenance.py), or of a movie's ("FIRST-LAST");
    `seconds` from the end of the frame before (or the start) to this one's, or of the frames rendered."""
    s = loaded.scene.settings
    return provenance(loaded.path, job.width, job.height, samples=s.samples, max_depth=s.max_depth, frame=frame,
                      block_size=job.block_size, gamma=job.gamma, engine=engine or "none", seconds=seconds)


def local_frames(loaded, todo: list[int], job, workers: int, changes: dict, progress=None):
    """(frame, image, stats) of each frame to do, one after another on this machine's cores."""
    for i, k in enumerate(todo):
        scene = loaded.scene if k == loaded.frame else apply(loaded.animation.scene(k), changes)
        step = None if progress is None else (lambda done, total, i=i: progress(i * total + done, len(todo) * total))
        image, s = render_tiles(scene, job, workers, step)
        yield k, image, s


def _read_back(path: str, job) -> np.ndarray:
    """A frame written by an earlier run, for a movie: decoded only when its header says it is
    of the job's size, so it takes no more memory than the frame rendered would."""
    try:
        with _frame_file(path, job.width, job.height) as img:
            if img.size != (job.width, job.height):
                raise RtcliError(f"{shown(path)}: an earlier frame of {img.size[0]}x{img.size[1]}, not "
                                 f"{job.width}x{job.height}: render it again (without --skip-existing)")
            pixels = np.asarray(img.convert("RGB"))
    except Image.DecompressionBombError:
        raise RtcliError(f"{shown(path)}: an earlier frame larger than {job.width}x{job.height}: render it "
                         "again (without --skip-existing)") from None
    except (OSError, UnidentifiedImageError, ValueError) as e:
        reason = " ".join(str(e).split()) or type(e).__name__
        raise RtcliError(f"{shown(path)}: cannot read this earlier frame for the movie: {reason}") from None
    return pixels
