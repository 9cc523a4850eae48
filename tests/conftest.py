"""Fixtures and options shared by the tests (plain helpers: helpers.py)."""

from __future__ import annotations

import pytest
from helpers import scene_from_yaml


def pytest_addoption(parser):
    parser.addoption("--update-goldens", action="store_true",
                     help="re-render missing or failing golden images (refused when CI is set)")


@pytest.fixture
def yaml_scene(tmp_path):
    return lambda text, name="scene.yaml": scene_from_yaml(text, tmp_path, name)
