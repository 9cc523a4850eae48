"""`rtcli render --watch`: a real process that renders, re-renders on edits of the scene and of
what it includes, prints a broken edit's error and goes on, and ends on Ctrl-C.

Waits poll the process's output with generous deadlines (the machine is shared); no
assertion is about time.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import types

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rtcli import api
from rtcli.cli import main
from rtcli.errors import SceneError
from rtcli.rendering import watch as watching
from rtcli.rendering.watch import watch
from rtcli.scenefile.reuse import Kept, reusing

SCENE = """\
include: [mat.yaml]
image: {width: 32, height: 24}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [0, 0, 5]}]
ambient: [0, 0, 0]
objects:
  - {name: ball, sphere: {radius: %s}, material: paint}
"""
PAINT = "materials:\n  paint: {diffuse: %s}\n"
DEADLINE = 60                                 # seconds; a first render takes about one


def wait_for(what, proc, deadline=DEADLINE):
    """Poll until what() is true; fail (killing the process) if the deadline passes or it ends."""
    end = time.monotonic() + deadline
    while not what():
        if proc.poll() is not None or time.monotonic() > end:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            pytest.fail(f"gave up waiting (exit code {proc.returncode})")
        time.sleep(0.05)


def pixel(path, row: int = 12) -> str:
    """The color of the image's pixel (row, 16): red, green or black."""
    with Image.open(path) as img:
        r, g, b = (int(c) for c in np.asarray(img)[row, 16])
    names = {(True, False, False): "red", (False, True, False): "green", (False, False, False): "black"}
    return names.get((r > 100, g > 100, b > 100), "?") if sorted((r, g, b))[1] == 0 else "?"


@pytest.mark.skipif(os.name != "posix", reason="signals a process group")
def test_watch_renders_each_edit_reports_errors_and_ends_on_ctrl_c(tmp_path):
    work, logs = tmp_path / "work", tmp_path / "logs"
    work.mkdir(), logs.mkdir()
    (work / "s.yaml").write_text(SCENE % 1)
    (work / "mat.yaml").write_text(PAINT % "[1, 0, 0]")
    out, err = open(logs / "out", "w"), open(logs / "err", "w")
    proc = subprocess.Popen([sys.executable, "-m", "rtcli", "render", "s.yaml", "--watch", "--workers", "1",
                             "--engine", "numpy"], cwd=work, stdout=out, stderr=err, start_new_session=True)
    rendered = lambda: (logs / "out").read_text().count(" rendered s.png (32x24) in ")    # noqa: E731
    try:
        wait_for(lambda: rendered() == 1, proc)
        assert pixel(work / "s.png") == "red"

        (work / "mat.yaml").write_text(PAINT % "[0, 1, 0]")             # an included file changes
        wait_for(lambda: rendered() == 2, proc)
        assert pixel(work / "s.png") == "green"

        (work / "s.yaml").write_text((SCENE % 1).replace("radius", "raduis"))      # a broken edit
        wait_for(lambda: "raduis" in (logs / "err").read_text(), proc)
        assert re.fullmatch(r"\d\d:\d\d:\d\d error: s\.yaml:7:27: objects\[0\]\.sphere\.raduis: unknown key "
                            r"\(did you mean 'radius'\?\); allowed here: center, radius\n", (logs / "err").read_text())
        assert proc.poll() is None and pixel(work / "s.png") == "green"       # still watching, image kept

        (work / "s.yaml").write_text(SCENE % 0.3)                          # fixed: a smaller ball
        wait_for(lambda: rendered() == 3, proc)
        assert pixel(work / "s.png") == "green" and pixel(work / "s.png", row=8) == "black"
    finally:
        os.killpg(proc.pid, signal.SIGINT)                                 # Ctrl-C in a terminal
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        out.close(), err.close()
    assert proc.returncode == 130
    assert (logs / "err").read_text().splitlines()[-1] == "error: interrupted"
    lines = (logs / "out").read_text().splitlines()
    assert lines[0] == "watching s.yaml and the files it reads; Ctrl-C ends" and len(lines) == 4
    assert sorted(os.listdir(work)) == ["mat.yaml", "s.png", "s.yaml"]          # no temporary file left


@pytest.fixture
def patience(monkeypatch):
    """The in-process watches below poll every 0.02 s; after 1,500 polls (half a minute) a test
    that waits for a change never seen fails instead of hanging."""
    polls = []

    def sleep(seconds):
        polls.append(seconds)
        if len(polls) > 1500:
            pytest.fail("the watch never saw the change")
        time.sleep(seconds)
    monkeypatch.setattr(watching, "time", types.SimpleNamespace(sleep=sleep))


def test_watch_waits_for_a_file_a_failed_load_looked_for(tmp_path, patience):
    """A scene that includes a file not there yet fails; creating the file renders it."""
    (tmp_path / "s.yaml").write_text(SCENE % 1)
    errors, loaded = [], []

    def render():
        loaded.append(api.load_scene(str(tmp_path / "s.yaml")))
        raise KeyboardInterrupt                                            # ends the watch

    def error(line):
        errors.append(line)
        (tmp_path / "mat.yaml").write_text(PAINT % "0.5")                 # made after the load looked for it
    with pytest.raises(KeyboardInterrupt):
        watch(str(tmp_path / "s.yaml"), render, error, poll=0.02)
    assert errors == [f"error: {tmp_path}/s.yaml:1:11: include[0]: file not found: {tmp_path}/mat.yaml"]
    assert len(loaded) == 1 and loaded[0].model.objects[0].name == "ball"


def test_a_save_during_a_render_is_rendered_after_it(tmp_path, patience):
    """The files are stamped as the load reads them: an edit made while rendering is seen."""
    (tmp_path / "s.yaml").write_text(SCENE % 1)
    (tmp_path / "mat.yaml").write_text(PAINT % "0.5")
    radii = []

    def render():
        radii.append(api.load_scene(str(tmp_path / "s.yaml")).model.objects[0].shape.radius)
        if len(radii) == 2:
            raise KeyboardInterrupt
        (tmp_path / "s.yaml").write_text(SCENE % 0.5)                      # saved while "rendering"
    with pytest.raises(KeyboardInterrupt):
        watch(str(tmp_path / "s.yaml"), render, pytest.fail, poll=0.02)
    assert radii == [1, 0.5]


def test_watch_takes_one_scene(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("a.yaml", "b.yaml"):
        (tmp_path / name).write_text(SCENE % 1)
    result = CliRunner().invoke(main, ["render", "a.yaml", "b.yaml", "--watch"])
    assert (result.exit_code, result.output) == (2, "error: --watch renders one scene file\n")


@pytest.fixture
def one_render(tmp_path, monkeypatch):
    """s.yaml in the current folder, and a watch that renders once, then is interrupted."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE % 1)
    (tmp_path / "mat.yaml").write_text(PAINT % "[1, 0, 0]")

    def once(scene, render, error, poll=None):
        render()
        raise KeyboardInterrupt
    monkeypatch.setattr(watching, "watch", once)


def test_watch_with_view_writes_the_view(tmp_path, one_render):
    """--watch --view KIND writes NAME.KIND.png at every change (one render here, then Ctrl-C)."""
    result = CliRunner().invoke(main, ["render", "s.yaml", "--watch", "--view", "normal"])
    assert result.exit_code == 130 and " rendered s.normal.png (32x24) in " in result.output
    assert sorted(os.listdir(tmp_path)) == ["mat.yaml", "s.normal.png", "s.yaml"]


# --- meshes kept from one load to the next ---
MESH_SCENE = """\
camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
objects:
  - {mesh: {file: m.obj, smooth: %s}}
  - {mesh: {file: m.obj, smooth: true}}
"""
OCTAHEDRON = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\n"


def meshes(path, kept: Kept | None) -> list:
    """The shapes of the scene at `path`, loaded within reusing(kept) (or outside any watch)."""
    if kept is None:
        scene = api.load_scene(str(path))
    else:
        with reusing(kept):
            scene = api.load_scene(str(path))
    assert os.path.realpath(path.parent / "m.obj") in scene.inputs          # an input, reused or not
    return [o.shape for o in scene.model.objects]


def test_an_unchanged_mesh_is_reused_and_a_changed_one_read_again(tmp_path):
    (tmp_path / "m.obj").write_text(OCTAHEDRON)
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "false")
    path, kept = tmp_path / "s.yaml", Kept()
    first = meshes(path, kept)
    assert first[0] is not first[1] and first[0].smooth is False          # other parameters: another mesh
    again = meshes(path, kept)
    assert again[0] is first[0] and again[1] is first[1]
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "true")
    both_smooth = meshes(path, kept)
    assert both_smooth[0] is both_smooth[1] is first[1]
    (tmp_path / "m.obj").write_text(OCTAHEDRON + "f 1 6 3\n")                # the file changes
    changed = meshes(path, kept)
    assert changed[0] is not first[1] and len(changed[0]) == 5
    assert len(kept.previous) == 2                                          # the file's data and one mesh
    assert meshes(path, None)[0] is not meshes(path, None)[0]               # outside a watch: built each time


def test_a_reused_mesh_file_is_still_checked(tmp_path):
    (tmp_path / "m.obj").write_text(OCTAHEDRON)
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "true")
    kept = Kept()
    meshes(tmp_path / "s.yaml", kept)
    (tmp_path / "m.obj").unlink()
    with pytest.raises(SceneError, match=r"s\.yaml:3:.*objects\[0\]\.mesh\.file: file not found"):
        meshes(tmp_path / "s.yaml", kept)


def test_meshes_are_kept_across_a_broken_edit(tmp_path):
    """A load that fails before reaching a mesh does not make the next one build it again."""
    (tmp_path / "m.obj").write_text(OCTAHEDRON)
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "true")
    kept = Kept()
    first = meshes(tmp_path / "s.yaml", kept)
    (tmp_path / "s.yaml").write_text("include: [missing.yaml]\n" + MESH_SCENE % "true")
    with pytest.raises(SceneError, match="file not found"):
        meshes(tmp_path / "s.yaml", kept)
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "true")
    assert meshes(tmp_path / "s.yaml", kept)[0] is first[0]


def test_the_watch_reuses_a_mesh_whose_file_did_not_change(tmp_path, patience):
    (tmp_path / "m.obj").write_text(OCTAHEDRON)
    (tmp_path / "s.yaml").write_text(MESH_SCENE % "true")
    loaded = []

    def render():
        loaded.append(api.load_scene(str(tmp_path / "s.yaml")).model.objects)
        if len(loaded) == 3:
            raise KeyboardInterrupt
        if len(loaded) == 1:
            (tmp_path / "s.yaml").write_text(MESH_SCENE % "true" + "# an edit of the scene alone\n")
        else:
            (tmp_path / "m.obj").write_text(OCTAHEDRON + "f 1 6 3\n")
    with pytest.raises(KeyboardInterrupt):
        watch(str(tmp_path / "s.yaml"), render, pytest.fail, poll=0.02)
    first, second, third = ([o.shape for o in objects] for objects in loaded)
    assert second[0] is first[0] and third[0] is not first[0] and len(third[0]) == 5


def test_watch_renders_one_image_here(tmp_path, monkeypatch):
    """--watch goes with --frame N, not with a sequence, --skip-existing or a cluster."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.yaml").write_text(SCENE % 1)
    for extra, message in ((["--frames", "1-2"], "give --frame N"), (["-o", "f_%02d.png"], "give --frame N"),
                           (["--skip-existing"], "give --frame N"), (["--local-cluster", "2"], "no cluster option")):
        result = CliRunner().invoke(main, ["render", "a.yaml", "--watch", *extra])
        assert result.exit_code == 2 and message in result.output, (extra, result.output)


def test_the_scene_as_its_own_output_is_refused_before_watching(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE % 1)
    result = CliRunner().invoke(main, ["render", "s.yaml", "--watch", "-o", "s.yaml"])
    assert result.exit_code == 2 and "is an input of this run" in result.output
    assert (tmp_path / "s.yaml").read_text() == SCENE % 1


def test_watch_with_json_keeps_stdout_to_the_json_lines(one_render):
    """--stats --json: one JSON object per render on stdout; the watch's own lines on stderr."""
    import json
    result = CliRunner().invoke(main, ["render", "s.yaml", "--watch", "--stats", "--json"])
    assert result.exit_code == 130
    assert json.loads(result.stdout)["primary"] == 32 * 24
    assert "watching s.yaml" in result.stderr and " rendered s.png " in result.stderr
