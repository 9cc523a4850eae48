"""`rtcli render` of one scene or many: which files, which outputs, and the run.

Several SCENE arguments, or a folder (its *.yaml and *.yml files, not those of its
subfolders, which hold includes), render one image per scene into the folder -o
names (default: the current one), NAME.png for NAME.yaml, in one process: the
compiled engine's machine code is loaded once. Scenes are loaded one at a time
(memory holds one scene and one image); each image is staged in a temporary file,
and only when every scene has rendered are they all renamed into place, so a bad
scene anywhere leaves no output (writer.Staged). With --keep-going a broken scene
(an error while loading or rendering it) is reported and left out, and the others'
images are placed at the end (README.md, Commands).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable
from dataclasses import dataclass

from rtcli.errors import RtcliError, SceneError, error_line, shown
from rtcli.rendering.outputs import check_outputs
from rtcli.rendering.writer import FORMATS, Staged

SCENE_SUFFIXES = (".yaml", ".yml")


@dataclass(frozen=True)
class Item:
    scene: str                        # the scene file
    output: str                       # the image it renders to


def plan(args: list[str], output: str | None, suffix: str = ".png") -> tuple[list[Item], str | None]:
    """The (scene, output) pairs, and the folder -o names when it names one (else None); an output
    not named is the scene's name + suffix."""
    scenes = [s for arg in args for s in _scenes_of(arg)]
    if len(args) == 1 and scenes == [args[0]]:
        return [Item(args[0], output or _stem(args[0]) + suffix)], None
    folder = output or "."
    if os.path.splitext(folder)[1].lower() in FORMATS and not os.path.isdir(folder):
        raise RtcliError(f"{shown(folder)}: with several scenes, -o names a folder for their images")
    if os.path.exists(folder) and not os.path.isdir(folder):
        raise RtcliError(f"{shown(folder)}: with several scenes, -o names a folder, but this is a file")
    items, by_output = [], {}
    for scene in scenes:
        out = os.path.join(output, _stem(scene) + suffix) if output else _stem(scene) + suffix
        if out in by_output:
            raise RtcliError(f"{shown(by_output[out])} and {shown(scene)} would both render to {shown(out)}")
        by_output[out] = scene
        items.append(Item(scene, out))
    return items, folder


def _scenes_of(arg: str) -> list[str]:
    if not os.path.isdir(arg):
        return [arg]
    found = sorted(os.path.join(arg, n) for n in os.listdir(arg)
                   if n.lower().endswith(SCENE_SUFFIXES) and os.path.isfile(os.path.join(arg, n)))
    if not found:
        raise RtcliError(f"{shown(arg)}: a folder without .yaml scenes")
    return found


def _stem(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]


def run(items: list[Item], folder: str | None, load: Callable, render: Callable, *, ids: bool = False,
        keep_going: Callable | None = None, write: dict | None = None) -> list[tuple[Item, object, float]]:
    """Load and render each item, staging its image; all placed at the end, or none.

    `load(path)` returns an api.Scene, `render(scene, label)` its ImageArray (with `ids`, its
    16-bit id map), staged by its stage() with the options `write` (bit_depth, half, gamma). Returns (item, RenderStats, seconds from loading to staging) per scene.
    `keep_going(item, error)`, when given, receives the error of each scene that fails to load
    or render (RtcliError, MemoryError), which is then left out while the others are placed; the
    folder made for them stays, even empty. An error about the outputs (one that is an input of
    a scene, or cannot be written) still stops the run with nothing placed.
    """
    made = make_folder(folder)
    done, inputs, outputs = [], [], [(item.output, ids) for item in items]
    try:
        with Staged() as staged:
            for item in items:
                start = time.perf_counter()
                scene = _attempt(item, keep_going, load, item.scene)
                if scene is None:
                    continue
                inputs += scene.inputs
                check_outputs(outputs, inputs)
                image = _attempt(item, keep_going, render, scene, os.path.basename(item.scene))
                if image is None:
                    continue
                image.stage(staged, item.output, **(write or {}))
                done.append((item, image.stats, time.perf_counter() - start))
            staged.commit()
    except BaseException:
        if made:
            remove_folder(folder)
        raise
    return done


def _attempt(item: Item, keep_going: Callable | None, step: Callable, *args):
    """step(*args); with keep_going, None once the error of a broken scene is passed to it."""
    if keep_going is None:
        return step(*args)
    try:
        return step(*args)
    except (RtcliError, MemoryError) as error:
        keep_going(item, error)
        return None


def broken_line(item: Item, error: BaseException) -> str:
    """The error line of a scene --keep-going leaves out: a scene file's error is located in it; any
    other names the scene first, unless it does already."""
    line = error_line(error)
    if isinstance(error, SceneError) or str(error).startswith(f"{shown(item.scene)}:"):
        return line
    return line.replace("error: ", f"error: {shown(item.scene)}: ", 1)


def make_folder(folder: str | None) -> bool:
    """Create the output folder when it does not exist yet (its parent must); whether it was made."""
    if folder is None or os.path.isdir(folder):
        return False
    try:
        os.mkdir(folder)
    except OSError as e:
        raise RtcliError(f"{shown(folder)}: cannot create the output folder: {e.strerror or e}") from None
    return True


def remove_folder(folder: str) -> None:
    """Remove the folder if it is empty."""
    try:
        os.rmdir(folder)
    except OSError:
        pass


def stats_lines(done: list, as_json: bool, many: bool) -> list[str]:
    """What --stats prints: per scene the stats line (named when there are several), or JSON."""
    lines = []
    for item, stats, seconds in done:
        if as_json:
            lines.append(json.dumps({"scene": item.scene, "output": item.output, **stats.as_dict(),
                                     "wall_seconds": round(seconds, 6)}))
        else:
            lines.append((f"{shown(item.scene)}: " if many else "") + stats.line(seconds))
    return lines
