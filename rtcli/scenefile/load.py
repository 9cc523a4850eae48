"""A scene file -> its Scene, or its Animation: reading one that may be animated.

A scene file and its includes are read (yamlfile.py) with the garbage collector
paused and every file read recorded (files.reading_scene); then a still scene is
built by build.py, and a scene with an `animation:` section by animation.py, which
builds each frame with build.py; a still render of an animated scene shows frame 1
(docs/scene-format.md, Animation). This module stands above both: animation.py
imports build.py, and neither imports this one or the other way up.
"""

from __future__ import annotations

from rtcli.core.scene import Scene
from rtcli.scenefile import yamlfile
from rtcli.scenefile.animation import Animation
from rtcli.scenefile.build import build_scene
from rtcli.scenefile.files import reading_scene


def load_scene(path: str) -> Scene:
    """Read, check and build the scene at `path` (with its includes)."""
    return load_scene_and_inputs(path)[0]


def load_scene_and_inputs(path: str) -> tuple[Scene, list[str]]:
    """The scene, and the real paths of every file it read (scene, includes, meshes, textures),
    read with the garbage collector paused (files.reading_scene)."""
    with reading_scene() as inputs:
        scene = scene_from_docs(yamlfile.load(path))
    return scene, inputs


def scene_from_docs(docs: list) -> Scene:
    """Included documents first, the main file last; only the main file sets camera and image.
    An animated scene (an `animation:` section) gives its first frame."""
    if "animation" in docs[-1]:
        return Animation(docs).scene(1)
    return build_scene(docs)


def load_animation(path: str) -> tuple[Animation, Scene, list[str]]:
    """The scene file's animation (one frame for a still), its first frame, and the real paths
    of every file read (see load_scene_and_inputs). Later frames read no file: shapes and
    textures are shared."""
    with reading_scene() as inputs:
        animation = Animation(yamlfile.load(path))
        first = animation.scene(1)
    return animation, first, inputs
