"""`rtcli render` over the Python API: the same bytes, many scenes to a folder, --stats --json."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import same_image

import rtcli
from rtcli.cli import main

SCENE = """\
image: {width: 32, height: 24}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects:
  - {name: ball, sphere: {radius: 1}, material: {diffuse: [%s], reflection: 0.2}}
  - {name: floor, plane: {point: [0, -1, 0], normal: [0, 1, 0]}}
"""


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name, color in (("red", "1, 0, 0"), ("green", "0, 1, 0"), ("blue", "0, 0, 1")):
        (tmp_path / f"{name}.yaml").write_text(SCENE % color)
    runner = CliRunner()
    return lambda *args: runner.invoke(main, [*args, "--workers", "1"])


@pytest.mark.parametrize("options", [[], ["--samples", "2", "--gamma", "--width", "20"], ["--block-size", "4"]])
def test_the_command_line_and_the_api_write_identical_bytes(run, tmp_path, options):
    assert run("render", "red.yaml", "-o", "cli.png", *options).exit_code == 0
    kw = {"samples": 2, "gamma": True, "width": 20} if "--gamma" in options else {}
    kw.update({"block_size": 4} if "--block-size" in options else {})
    rtcli.render("red.yaml", output="api.png", workers=1, **kw)
    assert same_image(tmp_path / "cli.png", tmp_path / "api.png")


def test_signature_ids_match_the_api(run, tmp_path):
    assert run("signature", "red.yaml", "--ids", "ids.png", "-o", "sig.png").exit_code == 0
    rtcli.signature("red.yaml", workers=1, output="api-ids.png")
    assert same_image(tmp_path / "ids.png", tmp_path / "api-ids.png")


def test_several_scenes_render_into_the_folder_o_names(run, tmp_path):
    result = run("render", "red.yaml", "green.yaml", "-o", "out", "--stats", "--json", "--engine", "numpy")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["green.png", "red.png"]
    lines = [json.loads(line) for line in result.output.splitlines()]
    assert [(d["scene"], d["output"]) for d in lines] == [("red.yaml", "out/red.png"), ("green.yaml", "out/green.png")]
    assert all(d["primary"] == 32 * 24 and d["engine"] == "numpy" and d["total"] > d["primary"] for d in lines)
    assert run("render", "red.yaml", "-o", "alone.png", "--engine", "numpy").exit_code == 0
    assert same_image(tmp_path / "alone.png", tmp_path / "out" / "red.png")


def test_a_folder_renders_its_scenes_but_not_its_subfolders(run, tmp_path):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "materials.yaml").write_text("materials: {}\n")
    result = run("render", ".", "-o", "out", "--stats")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["blue.png", "green.png", "red.png"]
    assert result.output.splitlines()[0].startswith("./blue.yaml: rays: 768 primary")


def test_a_bad_scene_among_many_leaves_no_output(run, tmp_path):
    (tmp_path / "bad.yaml").write_text(SCENE.replace("radius: 1", "radius: -1") % "1, 1, 1")
    result = run("render", "red.yaml", "bad.yaml", "green.yaml", "-o", "out")
    assert result.exit_code == 2
    assert result.output == "error: bad.yaml:5:35: objects[0].sphere.radius: must be > 0, got -1\n"
    assert not (tmp_path / "out").exists()                           # the folder it made is gone too
    (tmp_path / "kept").mkdir()
    assert run("render", "red.yaml", "bad.yaml", "-o", "kept").exit_code == 2
    assert list((tmp_path / "kept").iterdir()) == []


BAD = SCENE.replace("radius: 1", "radius: -1") % "1, 1, 1"


def test_keep_going_renders_the_good_scenes_of_a_folder_and_exits_2(run, tmp_path):
    """A broken scene beside good ones: the good ones are written, one error line for the broken
    one, exit 2; stdout holds only the JSON lines of the rendered scenes."""
    (tmp_path / "bad.yaml").write_text(BAD)
    result = CliRunner().invoke(main, ["render", ".", "-o", "out", "--keep-going", "--stats", "--json",
                                       "--workers", "1", "--engine", "numpy"])
    assert result.exit_code == 2
    assert result.stderr == "error: ./bad.yaml:5:35: objects[0].sphere.radius: must be > 0, got -1\n"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["blue.png", "green.png", "red.png"]
    lines = [json.loads(line) for line in result.stdout.splitlines()]
    assert [d["scene"] for d in lines] == ["./blue.yaml", "./green.yaml", "./red.yaml"]
    assert run("render", "red.yaml", "-o", "alone.png", "--engine", "numpy").exit_code == 0
    assert same_image(tmp_path / "alone.png", tmp_path / "out" / "red.png", ignore=("scene",))


def test_without_keep_going_a_broken_scene_in_a_folder_writes_nothing(run, tmp_path):
    (tmp_path / "bad.yaml").write_text(BAD)
    result = run("render", ".", "-o", "out")
    assert result.exit_code == 2
    assert result.output == "error: ./bad.yaml:5:35: objects[0].sphere.radius: must be > 0, got -1\n"
    assert not (tmp_path / "out").exists()


def test_keep_going_reports_every_broken_scene_and_keeps_the_folder(run, tmp_path):
    """Scenes broken in loading (a missing file, bad YAML) and in rendering (a size too big) each get
    their line, in order; the folder is made even when no scene renders, for `compare` to list them."""
    (tmp_path / "bad.yaml").write_text(BAD)
    result = run("render", "bad.yaml", "missing.yaml", "red.yaml", "-o", "out", "--keep-going")
    assert result.exit_code == 2
    assert result.output.splitlines() == ["error: bad.yaml:5:35: objects[0].sphere.radius: must be > 0, got -1",
                                          "error: missing.yaml: file not found: missing.yaml"]
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["red.png"]
    result = run("render", "bad.yaml", "missing.yaml", "-o", "none", "--keep-going")
    assert result.exit_code == 2 and result.output.count("\n") == 2
    assert (tmp_path / "none").is_dir() and not list((tmp_path / "none").iterdir())
    result = run("render", "red.yaml", "green.yaml", "-o", "wide", "--keep-going", "--width", "20000")
    assert result.exit_code == 2
    assert [line[:30] for line in result.output.splitlines()] == ["error: red.yaml: 20000x15000 i",
                                                                  "error: green.yaml: 20000x15000"]
    assert not list((tmp_path / "wide").iterdir())


def test_keep_going_still_refuses_an_output_that_is_an_input(run, tmp_path):
    """Errors about the outputs are not a broken scene's: the run stops and nothing is written."""
    from PIL import Image
    (tmp_path / "out").mkdir()
    Image.new("RGB", (2, 2), (0, 255, 0)).save(tmp_path / "out" / "red.png")
    texture = (tmp_path / "out" / "red.png").read_bytes()
    (tmp_path / "tex.yaml").write_text(SCENE.replace("reflection: 0.2", "texture: {image: out/red.png}") % "1, 1, 1")
    result = run("render", "red.yaml", "tex.yaml", "-o", "out", "--keep-going")
    assert result.exit_code == 2
    assert result.output == "error: out/red.png: is an input of this run; it will not be overwritten (choose " \
                            "another output name)\n"
    assert (tmp_path / "out" / "red.png").read_bytes() == texture
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["red.png"]


def test_keep_going_takes_no_watch_or_frames(run):
    for extra in (["--watch"], ["--frames", "1-2"], ["-o", "f_%04d.png"]):
        result = run("render", "red.yaml", "--keep-going", *extra)
        assert result.exit_code == 2
        assert result.output.startswith("error: --keep-going renders the other scenes when one is broken")


@pytest.mark.parametrize("args, message", [
    (["red.yaml", "green.yaml", "-o", "x.png"], "x.png: with several scenes, -o names a folder for their images"),
    (["red.yaml", "sub/red.yaml"], "red.yaml and sub/red.yaml would both render to red.png"),
    (["red.yaml", "--json"], "--json goes with --stats"),
    (["empty"], "empty: a folder without .yaml scenes"),
])
def test_usage_errors_of_many_scenes(run, tmp_path, args, message):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "red.yaml").write_text(SCENE % "1, 0, 0")
    (tmp_path / "empty").mkdir()
    result = run("render", *args)
    assert result.exit_code == 2
    assert result.output == f"error: {message}\n"
    assert not list(tmp_path.glob("*.png"))


def test_one_scene_keeps_the_stats_line(run):
    result = run("render", "red.yaml", "--stats")
    assert result.exit_code == 0
    assert result.output.startswith("rays: 768 primary, ") and result.output.count("\n") == 1
    data = json.loads(run("render", "red.yaml", "--stats", "--json").output)
    assert data["width"] == 32 and data["height"] == 24 and np.isclose(data["total"], data["primary"]
                                                                       + data["shadow"] + data["reflected"]
                                                                       + data["refracted"])


def test_an_interrupt_between_scenes_leaves_no_image_and_no_folder(tmp_path):
    """SIGTERM while the second scene renders: the first scene's staged image and the folder go too."""
    import os
    import signal
    import subprocess
    import sys
    import time

    from helpers import SLOW
    (tmp_path / "fast.yaml").write_text(SCENE % "1, 0, 0")
    (tmp_path / "slow.yaml").write_text(SLOW)
    proc = subprocess.Popen([sys.executable, "-m", "rtcli", "render", "fast.yaml", "slow.yaml", "-o", "out",
                             "--engine", "numpy", "--workers", "1"], cwd=tmp_path, stderr=subprocess.PIPE,
                            start_new_session=True)
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob("out/.rtcli-*.png")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    time.sleep(0.5)                                    # the slow scene is being traced
    os.killpg(proc.pid, signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert (proc.returncode, err.decode()) == (143, "error: interrupted\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fast.yaml", "slow.yaml"]
