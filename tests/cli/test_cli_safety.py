"""The command line with hostile arguments and a new user's first hour.

Outputs never destroy anything, the format follows the extension, several
outputs are written all or none, extreme but legal scenes render without a word
on stderr, sizes are bounded, and the help leads somewhere.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rtcli.cli import main
from rtcli.kernels import variants
from rtcli.rendering import writer

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


def one_error(result) -> str:
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error: ") and result.output.count("\n") == 1, result.output
    return result.output[len("error: "):-1]


# --- outputs never destroy anything ---
def test_output_equal_to_the_scene_is_refused(run, tmp_path):
    before = (tmp_path / "s.yaml").read_bytes()
    for name in ("s.yaml", "./s.yaml", str(tmp_path / "s.yaml")):
        assert one_error(run("render", "s.yaml", "-o", name)).endswith(
            "is an input of this run; it will not be overwritten (choose another output name)")
    assert (tmp_path / "s.yaml").read_bytes() == before


def test_output_linked_to_an_input_is_refused(run, tmp_path):
    """A hard link, or a symlink named .png, is the same file as the input."""
    os.link(tmp_path / "s.yaml", tmp_path / "hard.png")
    os.symlink(tmp_path / "s.yaml", tmp_path / "soft.png")
    for name in ("hard.png", "soft.png"):
        assert "is an input of this run" in one_error(run("render", "s.yaml", "-o", name))


@pytest.mark.parametrize("kind", ["include", "mesh", "texture"])
def test_output_equal_to_any_input_is_refused(run, tmp_path, kind):
    Image.new("RGB", (4, 4), (0, 255, 0)).save(tmp_path / "tex.png")
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "inc.yaml").write_text("objects: [{sphere: {}}]\n")
    extra = {"include": ("include: [inc.yaml]\n", "inc.yaml"),
             "mesh": ("  - {mesh: {file: m.obj}}\n", "m.obj"),
             "texture": ("  - {sphere: {}, material: {texture: {image: tex.png}}}\n", "tex.png")}[kind]
    (tmp_path / "t.yaml").write_text(SCENE + extra[0] if kind != "include" else extra[0] + SCENE)
    before = (tmp_path / extra[1]).read_bytes()
    out = extra[1] if kind == "texture" else extra[1] + ".png"
    if kind != "texture":
        os.symlink(tmp_path / extra[1], tmp_path / out)
    assert "is an input of this run" in one_error(run("render", "t.yaml", "-o", out))
    assert (tmp_path / extra[1]).read_bytes() == before


def test_two_outputs_of_signature_must_differ(run, tmp_path):
    assert one_error(run("signature", "s.yaml", "-o", "a.png", "--ids", "a.png")) == (
        "a.png: given for two outputs; they must differ")
    assert not (tmp_path / "a.png").exists()


def test_compare_outputs_must_not_be_its_inputs(run, tmp_path):
    Image.new("RGB", (8, 8)).save(tmp_path / "a.png")
    Image.new("RGB", (8, 8), (9, 9, 9)).save(tmp_path / "b.png")
    before = (tmp_path / "a.png").read_bytes()
    assert "is an input of this run" in one_error(run("compare", "a.png", "b.png", "--diff", "a.png"))
    assert (tmp_path / "a.png").read_bytes() == before


@pytest.mark.parametrize("target, kind", [("folder.png", "a folder"), ("fifo.png", "a FIFO (named pipe)"),
                                          ("/dev/null", "a character device")])
def test_output_that_is_not_a_regular_file_is_never_replaced(run, tmp_path, target, kind):
    (tmp_path / "folder.png").mkdir()
    os.mkfifo(tmp_path / "fifo.png")
    assert one_error(run("render", "s.yaml", "-o", target)) == (
        f"{target}: is {kind}, not a regular file; it will not be replaced")
    assert (tmp_path / "folder.png").is_dir() and os.path.exists(tmp_path / "fifo.png")


@pytest.mark.parametrize("option", ["-o", "--ids"])
def test_empty_output_is_a_usage_error(run, option):
    args = ["signature", "s.yaml", option, ""]
    assert one_error(run(*args)).endswith("must not be empty")


def test_format_follows_the_extension(run, tmp_path):
    assert run("render", "s.yaml", "-o", "x.jpg", "--workers", "1").exit_code == 0
    assert (tmp_path / "x.jpg").read_bytes()[:3] == b"\xff\xd8\xff"                 # JPEG, never PNG bytes
    assert Image.open(tmp_path / "x.jpg").format == "JPEG"
    assert run("render", "s.yaml", "-o", "x.bmp", "--workers", "1").exit_code == 0
    assert Image.open(tmp_path / "x.bmp").format == "BMP"
    assert one_error(run("render", "s.yaml", "-o", "x.yaml")).startswith(
        "x.yaml: the output format follows the extension: '.yaml' is not one of .png, .jpg")
    assert "no extension" in one_error(run("render", "s.yaml", "-o", "x"))
    assert one_error(run("signature", "s.yaml", "--ids", "ids.jpg")) == (
        "ids.jpg: an id map is written as a 16-bit PNG: the name must end in .png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml", "x.bmp", "x.jpg"]


def test_when_one_of_two_outputs_fails_none_is_left(run, tmp_path, monkeypatch):
    """signature -o X --ids Y: if Y cannot be written, X is not left either."""
    real = writer._write_temp

    def failing(path, pixels, *rest):
        if path.endswith("ids.png"):
            raise OSError(28, "No space left on device")
        return real(path, pixels, *rest)
    monkeypatch.setattr(writer, "_write_temp", failing)
    assert one_error(run("signature", "s.yaml", "-o", "sig.png", "--ids", "ids.png", "--workers", "1")) == (
        "cannot write ids.png: No space left on device")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_a_failed_rename_removes_the_outputs_already_placed(tmp_path, monkeypatch):
    real = os.replace
    calls = []

    def second_fails(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError(5, "Input/output error")
        real(src, dst)
    monkeypatch.setattr(os, "replace", second_fails)
    pixels = np.zeros((2, 2, 3), np.uint8)
    with pytest.raises(Exception, match="cannot write .*b.png: Input/output error"):
        writer.write_images([(str(tmp_path / "a.png"), pixels), (str(tmp_path / "b.png"), pixels)])
    assert list(tmp_path.iterdir()) == []


# --- legal extremes render silently ---
EXTREME = """\
image: {width: 24, height: 18}
camera: {eye: [1e12, 1e12, 1e12], look_at: [0, 0, 0], fov: 40}
render: {max_depth: 64}
ambient: [1e20, 1e20, 1e20]
lights: [{position: [1e20, 5, 5], color: [1e20, 1e20, 1e20], attenuation: [1e20, 1e20, 1e20],
          area: {u: [1e20, 0, 0], v: [0, 1e20, 0]}}]
objects:
  - {sphere: {radius: 1e18}, material: {reflection: 1, transmission: 1, ior: 1e20, specular: 1e20, shininess: 1e20}}
  - {triangle: {vertices: [[0, 0, 0], [1e20, 0, 0], [0, 1e20, 0]]}}
  - {box: {max: [1e20, 1e20, 1e20]}, material: {texture: {checker: {colors: [[1, 0, 0], [0, 1, 0]], size: 1e-20}}}}
  - {cone: {radius: 1e20, top: [0, 1e20, 0]}}
  - {cylinder: {radius: 1e20, top: [0, 1e20, 0]}, transform: [{scale: 1e-20}]}
  - {plane: {point: [1e20, 1e20, 1e20], normal: [1e20, 1e-20, 0]}}
  - {sphere: {}, transform: [{scale: 1e20}, {rotate: {axis: [1, 1, 0], degrees: 1e20}}]}
  - {polygon: {vertices: [[0, 0, 0], [1e20, 0, 0], [1e20, 1e20, 0], [0, 1e20, 0]]}}
  - {torus: {major: 1e20, minor: 1e19}}
  - {sphere: {center: [-1e20, 0, 0], radius: 1e-20}}
"""


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_legal_extreme_values_render_without_a_word_on_stderr(tmp_path, engine):
    text = EXTREME
    if engine == "compiled":
        if not variants.ENABLED:
            pytest.skip("numba is not installed")
    (tmp_path / "x.yaml").write_text(text)
    result = subprocess.run([sys.executable, "-W", "error", "-m", "rtcli", "render", "x.yaml", "--workers", "1",
                             "--engine", engine, "-o", "x.png"], cwd=tmp_path, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    lines = result.stderr.splitlines()             # only the scene's own warnings (lint.py), no numpy or Python one
    assert all(re.fullmatch(r"x\.yaml:\d+:\d+: [\w\[\].]+: warning: .*", line) for line in lines), lines
    assert Image.open(tmp_path / "x.png").size == (24, 18)


# --- sizes ---
def test_an_image_too_large_for_memory_is_refused_up_front(run, tmp_path):
    assert one_error(run("render", "s.yaml", "--width", "32768", "--height", "32768")) == (
        "32768x32768 is 1,073,741,824 pixels, more than the 268,435,456 allowed "
        "(16384 x 16384; rendering keeps the whole image in memory)")
    (tmp_path / "big.yaml").write_text(SCENE.replace("{width: 32, height: 24}", "{width: 32768, height: 32768}"))
    assert one_error(run("validate", "big.yaml")).startswith("big.yaml:1:8: image: 32768x32768 is ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.yaml", "s.yaml"]


def test_compare_refuses_huge_images_from_their_header(run, tmp_path):
    Image.new("1", (10000, 10000)).save(tmp_path / "a.png")          # a few kB on disk, 300 MB decoded
    assert one_error(run("compare", "a.png", "a.png")) == (
        "a.png: more than the 40,000,000 pixels rtcli compare accepts")


# --- the first hour ---
def test_no_arguments_shows_the_help():
    result = subprocess.run([sys.executable, "-m", "rtcli"], capture_output=True, text=True)
    assert result.returncode == 0 and "Usage:" in result.stdout and "render" in result.stdout


def test_help_points_to_the_scene_format(run):
    assert "docs/scene-format.md" in run("--help").output
    assert "docs/scene-format.md" in run("render", "--help").output


@pytest.mark.parametrize("camera", [
    "{eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}",
    "{eye: [0, 0, 5], look_at: [0, 0, 0], window: {left: -1, right: 1, top: 0.75, bottom: -0.75}}",
    "{eye: [0, 0, 5], screen: {lower_left: [-1, -0.75, 0], horizontal: [2, 0, 0], vertical: [0, 1.5, 0]}}",
])
@pytest.mark.parametrize("given, size", [(("--width", "64"), (64, 48)), (("--height", "12"), (16, 12))])
def test_width_or_height_alone_keeps_the_aspect_ratio(run, tmp_path, camera, given, size):
    (tmp_path / "c.yaml").write_text(SCENE.replace("{eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}", camera))
    result = run("render", "c.yaml", "-o", "c.png", "--workers", "1", *given)
    assert (result.exit_code, result.output) == (0, "")
    assert Image.open(tmp_path / "c.png").size == size


def test_stretching_a_window_camera_prints_a_note(run, tmp_path):
    camera = "{eye: [0, 0, 5], look_at: [0, 0, 0], window: {left: -1, right: 1, top: 0.75, bottom: -0.75}}"
    (tmp_path / "c.yaml").write_text(SCENE.replace("{eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}", camera))
    result = run("render", "c.yaml", "-o", "c.png", "--workers", "1", "--width", "40", "--height", "40")
    assert result.exit_code == 0
    assert result.output == "note: the window camera keeps its rectangle, so the 32x24 scene stretches to 40x40\n"
    assert run("render", "s.yaml", "--width", "40", "--height", "40", "--workers", "1").output == ""   # fov


def test_width_whose_height_would_exceed_the_limit(run):
    assert one_error(run("render", "s.yaml", "--width", "32768", "--height", "32768")).startswith("32768x32768")
    tall = SCENE.replace("{width: 32, height: 24}", "{width: 10, height: 1000}")
    with open("tall.yaml", "w") as f:
        f.write(tall)
    assert one_error(run("render", "tall.yaml", "--width", "400")) == (
        "--width 400 makes the height 40000 (keeping the scene's 10x1000 aspect ratio), more than 32768")


def test_install_hints_never_name_the_package_index(run, monkeypatch):
    monkeypatch.setattr(variants, "ENABLED", False)
    message = one_error(run("render", "s.yaml", "--engine", "compiled"))
    assert "pip install -e '.[fast]'" in message and "rtcli[" not in message
    assert "pip install -e '.[flip]'" in run("compare", "--help").output.replace("\n", " ").replace("  ", " ")


def test_readme_tells_how_to_run_rtcli_after_make_demo():
    readme = open(os.path.join(os.path.dirname(__file__), "..", "..", "README.md")).read()
    assert ". .venv/bin/activate" in readme and ".venv/bin/rtcli" in readme
    assert "pip install rtcli" not in readme and "'rtcli[" not in readme
