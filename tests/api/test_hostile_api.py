"""Hostile arguments to the Python API and NUL bytes in paths: rtcli's own error, naming the argument.

The API promises rtcli.RtcliError with a one-line message for bad input (docs/python-api.md,
Errors); the command line gives one `error:` line and exit 2 for a path with a NUL byte,
wherever the path is written (an argument, an include, a mesh, a texture).
"""

from __future__ import annotations

import math
import os
import pathlib
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import rtcli
from rtcli.cli import main

SCENE = """\
camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
image: {width: 8, height: 6}
lights: [{position: [5, 5, 5]}]
objects: [{sphere: {}}]
"""
IMAGE = np.zeros((4, 4, 3), np.uint8)


@pytest.fixture
def scenes(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RTCLI_NUMBA", "0")
    (tmp_path / "s.yaml").write_text(SCENE)
    (tmp_path / "a.yaml").write_text(SCENE + "animation: {fps: 4, frames: 3}\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rtcli.load_scene("s.yaml"), rtcli.load_scene("a.yaml")


def api_error(call) -> str:
    with pytest.raises(rtcli.RtcliError) as e:
        call()
    message = str(e.value)
    assert "\n" not in message and len(message) < 300, message
    return message


@pytest.mark.parametrize("call, message", [
    (lambda s, a: a.at(None), "frame must be an integer in 1..100000, got None"),
    (lambda s, a: a.at(4), "frame 4: a.yaml has 3 frames (1-3)"),
    (lambda s, a: rtcli.diff(IMAGE, IMAGE, tolerance=-1), "tolerance must be an integer in 0..255, got -1"),
    (lambda s, a: rtcli.diff(IMAGE, IMAGE, max_cluster=1.5), "max_cluster must be an integer >= 0, got 1.5"),
    (lambda s, a: rtcli.diff(IMAGE, IMAGE, max_bad_fraction=math.nan), "max_bad_fraction must be a number in 0..1, got nan"),
    (lambda s, a: rtcli.diff(IMAGE, IMAGE, flip="yes"), "flip must be True or False, got 'yes'"),
    (lambda s, a: rtcli.diff("a\0.png", IMAGE), "actual 'a\\x00.png': a path cannot hold a NUL byte"),
    (lambda s, a: rtcli.render(s, output="o\0.png"), "output 'o\\x00.png': a path cannot hold a NUL byte"),
    (lambda s, a: rtcli.render(s, output=3), "output must be a path (a str or os.PathLike), got 3"),
    (lambda s, a: rtcli.render(s, progress="bar"), "progress must be a function (or None), got 'bar'"),
    (lambda s, a: rtcli.render(s, notes=1), "notes must be a function (or None), got 1"),
    (lambda s, a: rtcli.render(s, workers=10 ** 5000), "workers must be an integer in 1..256, got a value of type int"),
    (lambda s, a: rtcli.render(s, engine=None), "engine must be auto, numpy or compiled, got None"),
    (lambda s, a: rtcli.signature(s, output=pathlib.Path("i\0.png")), "output 'i\\x00.png': a path cannot hold a NUL byte"),
    (lambda s, a: rtcli.view(s, "depth", tile=None), "tile must be an integer in 1..4096, got None"),
    (lambda s, a: rtcli.view(s, ["depth"]), "the view must be one of normal, depth, uv, albedo, bounces, ids, got ['depth']"),
    (lambda s, a: rtcli.explain(s, 1, 1, gamma="no"), "gamma must be True or False, got 'no'"),
    (lambda s, a: rtcli.explain(s, 1, 1).json(sample=1), "sample must be None (every one) or an integer in 0..0, got 1"),
    (lambda s, a: rtcli.legend(s, np.array([[0, 7]])), "ids holds 7, not an id of this scene (0 for the background, 1..1 its objects)"),
    (lambda s, a: rtcli.legend(s, "ids"), "ids must be an array of object ids (rtcli.signature's), got 'ids'"),
    (lambda s, a: s.override(width="wide"), "width must be an integer in 1..32768, got 'wide'"),
    (lambda s, a: rtcli.render(s).save(None), "path must be a path (a str or os.PathLike), got None"),
    (lambda s, a: rtcli.render(s).to_8bit(gamma=None), "gamma must be True or False, got None"),
    (lambda s, a: rtcli.load_scene(b"s.yaml"), "a scene is a path, YAML text or a dict, not bytes"),
    (lambda s, a: rtcli.load_scene("s.yaml", folder="."), "folder= is for YAML text and dicts; a scene file's names "
                                                        "are relative to its folder"),
    (lambda s, a: rtcli.load_scene("{objects: []}", folder="d\0"), "folder 'd\\x00': a path cannot hold a NUL byte"),
])
def test_every_api_argument_is_checked(scenes, call, message):
    assert api_error(lambda: call(*scenes)) == message


def test_a_legend_of_huge_ids_takes_no_memory(scenes):
    """bincount of the ids would allocate 8 bytes an id up to the largest: refused first."""
    ids = np.array([[0, 2 ** 62]], np.int64)
    assert api_error(lambda: rtcli.legend(scenes[0], ids)).startswith(f"ids holds {2 ** 62}, not an id of this scene")


@pytest.mark.parametrize("source, message", [
    ("s\0.yaml", "'s\\x00.yaml': cannot read 's\\x00.yaml': a path cannot hold a NUL byte"),
    (pathlib.Path("s\0.yaml"), "'s\\x00.yaml': cannot read 's\\x00.yaml': a path cannot hold a NUL byte"),
    ({"include": ["a\0b.yaml"]}, "<dict>: include[0]: cannot read 'a\\x00b.yaml': a path cannot hold a NUL byte"),
    (SCENE.replace("{sphere: {}}", '{mesh: {file: "m\\0.obj"}}'),
     "<string>:4:25: objects[0].mesh.file: cannot read 'm\\x00.obj': a path cannot hold a NUL byte"),
])
def test_a_nul_byte_in_a_scene_path_is_a_scene_error(scenes, source, message):
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(source)
    assert str(e.value) == message


# --- the command line ---
def cli_error(*args) -> str:
    result = CliRunner().invoke(main, list(args))
    assert result.exit_code == 2, (result.output, result.exception)
    assert result.output.startswith("error: ") and result.output.count("\n") == 1, result.output
    return result.output[len("error: "):-1]


@pytest.mark.parametrize("name, line", [
    ("include", 'include: ["a\\0b.yaml"]\n'),
    ("mesh", SCENE.replace("{sphere: {}}", '{mesh: {file: "m\\0.obj"}}')),
    ("texture", SCENE.replace("{sphere: {}}", '{sphere: {}, material: {texture: {image: "t\\0.png"}}}')),
])
def test_a_nul_byte_in_a_path_inside_a_scene_is_located(scenes, tmp_path, name, line):
    (tmp_path / "n.yaml").write_text(line)
    for command in (["render", "n.yaml", "-o", "out.png"], ["validate", "n.yaml"]):
        message = cli_error(*command)
        assert message.startswith("n.yaml:") and message.endswith(": a path cannot hold a NUL byte"), message
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("args, message", [
    (["render", "s.yaml", "-o", "o\0.png"], "-o 'o\\x00.png'"),
    (["render", "s\0.yaml"], "'s\\x00.yaml'"),
    (["render", "a.yaml", "-o", "d\0/f_%d.png"], "-o 'd\\x00/f_%d.png'"),
    (["render", "a.yaml", "--movie=m\0.gif"], "--movie 'm\\x00.gif'"),
    (["signature", "s.yaml", "-o", "o.png", "--ids", "i\0.png"], "--ids 'i\\x00.png'"),
    (["compare", ".", "..", "--report", "r\0"], "--report 'r\\x00'"),
    (["explain", "s\0.yaml", "1", "1"], "'s\\x00.yaml'"),
])
def test_a_nul_byte_in_an_argument_is_one_line(scenes, tmp_path, args, message):
    assert cli_error(*args) == f"{message}: an argument cannot hold a NUL byte (a path cannot)"
    assert sorted(os.listdir(tmp_path)) == ["a.yaml", "s.yaml"]
