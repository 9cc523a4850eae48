"""The command line through click's CliRunner: exit codes 0/1/2 and one-line errors."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rtcli.cli import main

SCENE = """\
image: {width: 32, height: 24}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects:
  - {name: ball, sphere: {radius: 1}, material: {diffuse: [1, 0, 0]}}
"""


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE)
    runner = CliRunner()
    return lambda *args: runner.invoke(main, list(args))


@pytest.mark.parametrize("command", ["render", "signature", "compare", "validate", "presets"])
def test_help_of_each_command(run, command):
    result = run(command, "--help")
    assert result.exit_code == 0
    assert "Usage:" in result.output


def test_render_writes_default_output(run, tmp_path):
    result = run("render", "s.yaml", "--workers", "1")
    assert result.exit_code == 0, result.output
    img = np.asarray(Image.open(tmp_path / "s.png"))
    assert img.shape == (24, 32, 3)
    assert img[12, 16, 0] > 100 and img[12, 16, 1] == 0           # the red ball in the middle
    assert tuple(img[0, 0]) == (0, 0, 0)                            # black background


def test_render_size_override_and_stats(run, tmp_path):
    result = run("render", "s.yaml", "-o", "x.png", "--width", "10", "--height", "6", "--stats", "--workers", "1")
    assert result.exit_code == 0, result.output
    assert Image.open(tmp_path / "x.png").size == (10, 6)
    assert "60 primary" in result.output and "rays/s" in result.output


def test_scene_error_is_one_line_exit_2_and_no_output(run, tmp_path):
    (tmp_path / "bad.yaml").write_text(SCENE.replace("radius: 1", "radius: -1"))
    result = run("render", "bad.yaml")
    assert result.exit_code == 2
    assert result.output == "error: bad.yaml:5:35: objects[0].sphere.radius: must be > 0, got -1\n"
    assert not (tmp_path / "bad.png").exists()


def test_missing_scene_file(run):
    result = run("validate", "nope.yaml")
    assert result.exit_code == 2
    assert result.output == "error: nope.yaml: file not found: nope.yaml\n"


def test_usage_error_exit_2(run):
    result = run("render", "s.yaml", "--width", "0")
    assert result.exit_code == 2
    assert result.output.startswith("error: ") and result.output.count("\n") == 1


def test_validate_summary(run):
    result = run("validate", "s.yaml")
    assert result.exit_code == 0
    assert result.output.startswith("s.yaml: ok: 1 object (1 sphere), 1 light")


def test_presets_lists_brass(run):
    result = run("presets")
    assert result.exit_code == 0
    assert any(line.startswith("brass") and "27.8974" in line for line in result.output.splitlines())


def test_compare_exit_codes(run, tmp_path):
    a = np.zeros((20, 20, 3), np.uint8)
    b = a.copy()
    b[5:10, 5:10] = 200
    Image.fromarray(a).save(tmp_path / "a.png")
    Image.fromarray(b).save(tmp_path / "b.png")
    assert run("compare", "a.png", "a.png").exit_code == 0
    result = run("compare", "a.png", "b.png", "--diff", "d.png")
    assert result.exit_code == 1
    assert result.output.startswith("FAIL") and (tmp_path / "d.png").exists()
    assert run("compare", "a.png", "missing.png").exit_code == 2


def test_compare_id_maps_without_the_ids_flag(run, tmp_path):
    """Two 16-bit id maps are compared as id maps even without --ids."""
    ids = np.zeros((20, 20), np.uint16)
    ids[5:15, 5:15] = 3
    Image.fromarray(ids).save(tmp_path / "a.png")
    other = ids.copy()
    other[8:12, 8:12] = 4
    Image.fromarray(other).save(tmp_path / "b.png")
    assert run("compare", "a.png", "a.png").exit_code == 0
    result = run("compare", "a.png", "b.png")
    assert result.exit_code == 1 and "mismatched ids" in result.output


def test_compare_flip_map(run, tmp_path):
    """--flip writes FLIP's error map and adds the mean to the one summary line."""
    pytest.importorskip("flip_evaluator")
    a = np.full((32, 32, 3), 100, np.uint8)
    b = a.copy()
    b[8:16, 8:16] = 200
    Image.fromarray(a).save(tmp_path / "a.png")
    Image.fromarray(b).save(tmp_path / "b.png")
    same = run("compare", "a.png", "a.png", "--flip", "f0.png")
    assert same.exit_code == 0 and same.output.rstrip().endswith("mean FLIP 0.0000")
    result = run("compare", "a.png", "b.png", "--flip", "f.png")
    assert result.exit_code == 1 and result.output.count("\n") == 1
    assert float(result.output.split("mean FLIP ")[1]) > 0.01
    flip = np.asarray(Image.open(tmp_path / "f.png"))
    assert flip.shape == (32, 32, 3) and flip[12, 12].sum() > flip[28, 28].sum()
