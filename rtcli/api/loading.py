"""Scenes loaded: scene files for the command line (the frame asked for, the files' bytes for a
cluster, `rtcli validate`'s warnings), and a path, YAML text or a dict for the Python API, with
the same checks and the same located messages (docs/python-api.md).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Mapping
from dataclasses import dataclass, field

from rtcli.api.scene import Scene, Source, check_frame
from rtcli.errors import RtcliError
from rtcli.inspect import checks
from rtcli.inspect.lint import warn
from rtcli.scenefile import yamlfile
from rtcli.scenefile.animation import Animation
from rtcli.scenefile.files import collecting, reading_scene
from rtcli.scenefile.limits import MAX_SCENE_BYTES
from rtcli.scenefile.load import load_animation
from rtcli.scenefile.plain import DICT, tree_from_dict
from rtcli.scenefile.remarks import recording_remarks


@dataclass
class Loaded:
    """A scene file read for a command: its path, its animation, the scene of the frame asked for,
    the real paths of its inputs, the files' bytes when they go to a cluster (kept: {path as the
    loader named it: (real path, bytes)}, rtcli/cluster/bundle.py), and the warnings about frame 1
    when they were asked for (rtcli/inspect/lint.py)."""

    path: str
    animation: Animation
    scene: object
    frame: int
    inputs: list
    kept: dict | None = None
    warnings: list = field(default_factory=list)


def load_file(scene_file: str, frame: int | None = None, keep: bool = False, option: str = "--frame",
              lint: bool = False) -> Loaded:
    """The scene file with frame `frame` (default 1) built; `keep`: also the files' bytes;
    `option` names the frame in messages; `lint`: also `rtcli validate`'s warnings
    (rtcli/inspect/checks.py)."""
    with collecting() if keep else contextlib.nullcontext() as kept, \
            recording_remarks() if lint else contextlib.nullcontext() as remarks:
        animation, first, inputs = load_animation(scene_file)
    k = frame or 1
    check_frame(animation, k, scene_file, option)
    found = checks.warnings(first, remarks) if lint else []
    return Loaded(scene_file, animation, first if k == 1 else animation.scene(k), k, inputs, kept if keep else None,
                  found)


def load(source: Source, folder: str | None = None, frame: int | None = None, option: str = "frame") -> Scene:
    """The Scene of a path, YAML text or a dict (see rtcli.load_scene for which is which), at frame
    `frame` of an animated scene (default 1); `option` names the frame in messages. Its warnings
    (`rtcli validate`'s, about frame 1) are raised as Python warnings (rtcli.RtcliWarning)."""
    scene, found = _load(source, folder, frame, option)
    warn(found)
    return scene


def _load(source: Source, folder: str | None, frame: int | None, option: str):
    """The Scene and its warnings (checks.Remark)."""
    if isinstance(source, Mapping):
        tree, name = tree_from_dict(dict(source), folder or "."), DICT
    elif is_yaml_text(source):
        if len(source) > MAX_SCENE_BYTES:
            raise RtcliError(f"YAML text of {len(source):,} characters: more than a scene file may hold")
        tree, name = yamlfile.parse(source, "<string>", folder or "."), "<string>"
    elif isinstance(source, (str, os.PathLike)):
        if folder is not None:
            raise RtcliError("folder= is for YAML text and dicts; a scene file's names are relative to its folder")
        path = os.fspath(source)
        loaded = load_file(path, frame, option=option, lint=True)
        return of_loaded(loaded, path), loaded.warnings
    else:
        raise RtcliError(f"a scene is a path, YAML text or a dict, not {type(source).__name__}")
    with reading_scene() as inputs, recording_remarks() as remarks:
        animation = Animation(yamlfile.load_tree(tree))
        k = frame or 1
        check_frame(animation, k, name, option)
        first = animation.scene(1)
        model = first if k == 1 else animation.scene(k)
    found = checks.warnings(first, remarks)
    return Scene(model, name, inputs, None if animation.still else animation, k, warnings=found), found


def of_loaded(loaded, path: str) -> Scene:
    """The Scene of a scene file loaded for the command line (Loaded)."""
    animation = None if loaded.animation.still else loaded.animation
    return Scene(loaded.scene, path, loaded.inputs, animation, loaded.frame, warnings=loaded.warnings)


def is_yaml_text(source: object) -> bool:
    """A str holding a line break, or a flow mapping `{...}`, is YAML text; any other str a path."""
    return isinstance(source, str) and ("\n" in source or source.lstrip().startswith("{"))
