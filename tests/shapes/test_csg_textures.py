"""A checker lies in the own space of the object it is on (docs/scene-format.md, Textures), before
its `transform:`, whether that object stands alone, is a group's child or a csg's child; in both
engines."""

from __future__ import annotations

import numpy as np
import pytest

from rtcli.rendering.tiles import Job, render

W, H = 64, 48
HEAD = """
camera: {eye: [0, 1.5, -5], look_at: [0, 1, 0], fov: 40}
ambient: [1, 1, 1]
lights: [{position: [-3, 6, -5], color: [1, 1, 1]}]
background: [0.2, 0.3, 0.4]
objects:
"""
CHECKER = "{ambient: 0.3, diffuse: 0.7, texture: {checker: {colors: [[1, 0.9, 0.2], [0.1, 0.2, 0.8]], size: 0.45}}}"
OWN = "[{scale: [1.3, 0.8, 1]}, {rotate: {axis: [1, 1, 0], degrees: 35}}, {translate: [0.2, 1.1, 0.3]}]"
OUTER = "[{rotate: {axis: [0, 1, 0], degrees: 20}}, {translate: [-0.1, 0.1, 0]}]"
BALL = f"{{sphere: {{}}, material: {CHECKER}, transform: {OWN}}}"
FAR = "{sphere: {center: [0, 0, 90], radius: 0.01}}"
BOX = "{box: {min: [-9, -9, -9], max: [9, 9, 9]}}"
HOLDERS = {
    "plain": f"  - {BALL}\n",
    "group": f"  - {{transform: {OUTER}, group: {{objects: [{BALL}]}}}}\n",
    "union": f"  - {{transform: {OUTER}, csg: {{union: [{BALL}, {FAR}]}}}}\n",
    "intersection": f"  - {{transform: {OUTER}, csg: {{intersection: [{BALL}, {BOX}]}}}}\n",
    "nested": f"  - {{transform: {OUTER}, csg: {{intersection: [{{csg: {{union: [{BALL}, {FAR}]}}, "
              f"transform: [{{scale: 1}}]}}, {BOX}]}}}}\n",
}


def image(yaml_scene, holder: str, engine: str, extra: str = "") -> np.ndarray:
    plain = holder == "plain"
    text = HEAD + (f"  - {{sphere: {{}}, material: {CHECKER}, transform: {OWN[:-1]}, {OUTER[1:]}}}\n"
                   if plain else HOLDERS[holder]) + extra
    scene = yaml_scene(text)
    return render(scene, Job(W, H, engine=engine))[0].astype(int)


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
@pytest.mark.parametrize("holder", ["group", "union", "intersection", "nested"])
def test_a_child_checker_is_in_the_childs_own_space(yaml_scene, holder, engine):
    plain = image(yaml_scene, "plain", engine)
    there = image(yaml_scene, holder, engine)
    assert len(np.unique(plain.reshape(-1, 3), axis=0)) > 20        # both colors, lit and shaded
    np.testing.assert_array_equal(there, plain)


def test_the_engines_agree_on_csg_checkers(yaml_scene):
    for holder in ("union", "nested"):
        np.testing.assert_array_equal(image(yaml_scene, holder, "numpy"), image(yaml_scene, holder, "compiled"))


def test_an_inherited_checker_is_in_the_childs_space_too(yaml_scene):
    """The csg's checker on a child that names no material lies in the child's space, as a group's."""
    inherited = HEAD + (f"  - {{transform: {OUTER}, material: {CHECKER}, csg: {{union: [{{sphere: {{}}, "
                        f"transform: {OWN}}}, {FAR}]}}}}\n")
    a = render(yaml_scene(inherited), Job(W, H, engine="numpy"))[0].astype(int)
    np.testing.assert_array_equal(a, image(yaml_scene, "plain", "numpy"))
