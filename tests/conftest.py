"""Shared test helpers: scenes from YAML text, one-pixel renders."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from rtcli.render import Job, render_tile
from rtcli.scenefile import yamlfile
from rtcli.scenefile.build import scene_from_docs


def pytest_addoption(parser):
    parser.addoption("--update-goldens", action="store_true",
                     help="re-render missing or failing golden images (refused when CI is set)")


def scene_from_yaml(text: str, tmp_path=None, name: str = "scene.yaml"):
    """Build a Scene from YAML text; written to tmp_path when given (for includes and files)."""
    text = textwrap.dedent(text)
    if tmp_path is not None:
        path = tmp_path / name
        path.write_text(text)
        return scene_from_docs(yamlfile.load(str(path)))
    return scene_from_docs([yamlfile.parse(text, name)])


def one_pixel(scene, i: int = 0, j: int = 0, width=None, height=None) -> np.ndarray:
    """The float color of pixel (i, j), unclamped."""
    job = Job(width or scene.settings.width, height or scene.settings.height)
    color, _ = render_tile(scene, job, np.array([i]), np.array([j]))
    return color[0]


@pytest.fixture
def yaml_scene(tmp_path):
    return lambda text, name="scene.yaml": scene_from_yaml(text, tmp_path, name)
