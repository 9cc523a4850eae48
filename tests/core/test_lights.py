"""Spot and area lights (optional keys beyond the notes' point light)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import one_pixel

FLOOR = """
image: {{width: 1, height: 1}}
camera: {{eye: [{x}, 5, 0], look_at: [{x}, 0, 0], up: [0, 0, -1], fov: 1}}
ambient: [0, 0, 0]
lights: [{light}]
objects:
  - {{plane: {{}}, material: {{diffuse: 1, ambient: 0}}}}
{extra}
"""


def floor_pixel(yaml_scene, x, light, extra=""):
    """Brightness of the floor point (x, 0, 0) seen from straight above."""
    return one_pixel(yaml_scene(FLOOR.format(x=x, light=light, extra=extra)))[0]


def test_spot_light_lights_inside_its_cone_with_falloff(yaml_scene):
    """Inside the cone: I (N.L) cos^falloff; outside: nothing."""
    spot = "{position: [0, 2, 0], spot: {direction: [0, -1, 0], angle: 30, falloff: 2}}"
    centre = floor_pixel(yaml_scene, 0.0, spot)
    assert centre == pytest.approx(1.0, rel=1e-6)
    x = 2 * np.tan(np.radians(20))                       # 20 degrees off the axis: inside
    cos = np.cos(np.radians(20))
    assert floor_pixel(yaml_scene, x, spot) == pytest.approx(cos * cos ** 2, rel=1e-6)
    assert floor_pixel(yaml_scene, 2 * np.tan(np.radians(40)), spot) == 0.0


def test_area_light_gives_soft_shadows(yaml_scene):
    """A wall whose top edge splits the area light gives a half shadow; a point light all or nothing.

    Wall: x = 0, 0 <= y <= 1. Light at (0.5, 2, 0). From the floor point (x0, 0, 0), x0 < 0,
    a light point (xl, 2) is hidden exactly when xl > -x0: x0 = -0.5 hides half the square.
    """
    wall = "  - {polygon: {vertices: [[0, 0, -5], [0, 0, 5], [0, 1, 5], [0, 1, -5]]}}"
    area = "{position: [0.5, 2, 0], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 4}}"
    point = "{position: [0.5, 2, 0]}"
    lit = floor_pixel(yaml_scene, -0.5, area)
    half = floor_pixel(yaml_scene, -0.5, area, wall)
    assert 0.3 * lit < half < 0.7 * lit
    assert floor_pixel(yaml_scene, -0.4, point, wall) == 0.0
    assert floor_pixel(yaml_scene, -0.6, point, wall) > 0.3


def test_area_light_is_repeatable(yaml_scene):
    """The jitter is a hash of the hit point: the same scene gives the same value."""
    area = "{position: [0, 2, 0], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 3}}"
    assert floor_pixel(yaml_scene, 0.3, area) == floor_pixel(yaml_scene, 0.3, area)
