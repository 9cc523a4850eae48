"""Warnings where users look: `rtcli render` (one scene, several, frames, --watch) prints
`validate`'s warnings on stderr before tracing, --quiet hides them, --strict makes them errors;
the Python API raises them as rtcli.RtcliWarning. And the camera check's cheap proofs are sound."""

from __future__ import annotations

import json
import os
import re
import warnings

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import scene_from_yaml

import rtcli
from rtcli.cli import main
from rtcli.inspect import checks
from rtcli.rendering import watch as watching
from rtcli.wavefront.intersect import find_first_hit
from rtcli.wavefront.rays import Rays

SCENE = ("image: {width: 32, height: 24}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
         "lights: [{position: [0, 5, 5]}]\n"
         "objects: [{sphere: {}, material: {diffuse: [255, 128, 0]}}]\n")
COLOR = ("s.yaml:4:44: objects[0].material.diffuse: warning: [255, 128, 0] looks like 0-255 values, but colors "
         "run from 0 to 1 here: [1, 0.502, 0] or \"#ff8000\" (write 255.0 if more than 1 is meant)")
CLEAN = SCENE.replace("[255, 128, 0]", "[1, 0.5, 0]")
DARK = "image: {width: 32, height: 24}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nobjects: [{sphere: {}}]\n"
NO_LIGHTS = ("d.yaml:1:1: lights: warning: no lights: only ambient light and emission show (a light is "
             "{position: [x, y, z]})")


@pytest.fixture
def run(tmp_path, monkeypatch):
    """`rtcli ARGS` in tmp_path, where s.yaml is SCENE; returns the click Result."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE)
    return lambda *args: CliRunner().invoke(main, list(args))


def test_render_warns_about_a_0_255_color_before_tracing(run, tmp_path):
    result = run("render", "s.yaml")
    assert result.exit_code == 0, result.output
    assert (result.stdout, result.stderr) == ("", COLOR + "\n")
    assert (tmp_path / "s.png").exists()


def test_a_scene_without_mistakes_renders_in_silence(run, tmp_path):
    (tmp_path / "s.yaml").write_text(CLEAN)
    result = run("render", "s.yaml")
    assert (result.exit_code, result.output) == (0, "")


def test_quiet_hides_the_warnings(run, tmp_path):
    result = run("render", "s.yaml", "--quiet")
    assert (result.exit_code, result.output) == (0, "")
    assert (tmp_path / "s.png").exists()


def test_strict_makes_them_an_error_and_writes_nothing(run, tmp_path):
    (tmp_path / "d.yaml").write_text(DARK.replace("{sphere: {}}", "{sphere: {}, material: {diffuse: 200}}"))
    for args in (["s.yaml"], ["s.yaml", "--quiet"], ["d.yaml", "-o", "d.png"]):
        result = run("render", *args, "--strict")
        assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr == ("error: d.yaml:3:44: objects[0].material.diffuse: 200 looks like 0-255 values, but "
                             "colors run from 0 to 1 here: [0.784, 0.784, 0.784] or \"#c8c8c8\" (write 200.0 if more "
                             "than 1 is meant) (and 1 more warning)\n")
    assert sorted(os.listdir(tmp_path)) == ["d.yaml", "s.yaml"]


def test_json_keeps_stdout_pure_json(run, tmp_path):
    (tmp_path / "d.yaml").write_text(DARK)
    result = run("render", "s.yaml", "d.yaml", "-o", "out", "--stats", "--json")
    assert result.exit_code == 0, result.output
    assert [json.loads(line)["scene"] for line in result.stdout.splitlines()] == ["s.yaml", "d.yaml"]
    assert result.stderr.splitlines() == [COLOR, NO_LIGHTS]


def test_several_scenes_name_the_scene_that_includes_a_warned_file(run, tmp_path):
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "paint.yaml").write_text("materials:\n  paint: {diffuse: [0, 0, 200]}\n")
    for name in ("a", "b"):
        (tmp_path / f"{name}.yaml").write_text("include: [common/paint.yaml]\n" +
                                              CLEAN.replace("{diffuse: [1, 0.5, 0]}", "paint"))
    result = run("render", "a.yaml", "b.yaml", "-o", "out")
    assert result.exit_code == 0, result.output
    assert [line.split(": warning: ")[0] + " ... " + line.rsplit(" (", 1)[1] for line in result.stderr.splitlines()] \
        == ["common/paint.yaml:2:20: materials.paint.diffuse ... included by a.yaml)",
            "common/paint.yaml:2:20: materials.paint.diffuse ... included by b.yaml)"]
    result = run("render", "a.yaml", "b.yaml", "-o", "strict", "--strict")
    assert result.exit_code == 2 and not (tmp_path / "strict").exists()


def test_an_animation_warns_about_frame_1_before_its_first_frame(run, tmp_path):
    (tmp_path / "d.yaml").write_text("animation: {frames: 3}\n" + DARK)
    result = run("render", "d.yaml", "-o", "f%d.png")
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == [
        NO_LIGHTS,
        "note: the warnings are about frame 1 of 3 (the camera, lights and objects where the animation starts)"]
    result = run("render", "d.yaml", "-o", "g%d.png", "--strict")
    assert result.exit_code == 2 and not any(name.startswith("g") for name in os.listdir(tmp_path))


def test_watch_prints_the_warnings_of_each_load_after_the_time(run, tmp_path, monkeypatch):
    """Two loads (the first render and one change), then Ctrl-C: the warning twice, each after the time."""
    changes = []

    def one_change(seen, poll):
        changes.append(seen)
        if len(changes) % 2 == 0:
            raise KeyboardInterrupt
    monkeypatch.setattr(watching, "_wait_for_change", one_change)
    result = run("render", "s.yaml", "--watch")
    assert result.exit_code == 130
    stamped = [line for line in result.stderr.splitlines() if "warning" in line]
    assert [re.sub(r"^\d\d:\d\d:\d\d ", "", line) for line in stamped] == [COLOR, COLOR]
    result = run("render", "s.yaml", "--watch", "--strict")
    assert re.fullmatch(r"\d\d:\d\d:\d\d error: s\.yaml:4:44: objects\[0\]\.material\.diffuse: \[255, 128, 0\] .*",
                        result.stderr.splitlines()[0])


def test_validate_and_render_print_the_same_lines(run, tmp_path):
    (tmp_path / "d.yaml").write_text(DARK)
    for scene in ("s.yaml", "d.yaml"):
        assert run("validate", scene).stderr == run("render", scene).stderr != ""


# --- the Python API ---
def test_the_api_raises_the_warnings_where_the_scene_is_loaded(tmp_path):
    path = str(tmp_path / "s.yaml")
    (tmp_path / "s.yaml").write_text(SCENE)
    with pytest.warns(rtcli.RtcliWarning, match=r"s\.yaml:4:44: objects\[0\]\.material\.diffuse: \[255, 128, 0\] "
                                                r"looks like 0-255 values") as caught:
        scene = rtcli.load_scene(path)
    assert [w.filename for w in caught] == [__file__]                  # the caller's line, not rtcli's
    assert issubclass(rtcli.RtcliWarning, UserWarning)
    assert scene.warnings == (f"{path}{COLOR[6:]}",)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rtcli.render(scene, width=8)                                   # loaded already: no second warning
    with pytest.warns(rtcli.RtcliWarning, match="looks like 0-255 values"):
        rtcli.render(path, width=8)


def test_yaml_text_and_dicts_warn_too():
    with pytest.warns(rtcli.RtcliWarning, match=r"^<string>:1:1: lights: no lights"):
        rtcli.load_scene(DARK)
    with pytest.warns(rtcli.RtcliWarning, match=r"^<dict>: lights: no lights"):
        rtcli.load_scene({"camera": {"eye": [0, 0, 5], "look_at": [0, 0, 0]}, "objects": [{"sphere": {}}]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert rtcli.load_scene(CLEAN).warnings == ()


def test_every_load_warns_again_under_python_s_default_filter():
    """The default filter shows a warning once per line; a scene loaded again (a cell run again)
    must say it again, as every render does."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        for _ in range(2):
            rtcli.load_scene(DARK)
    assert [str(w.message)[:31] for w in caught] == ["<string>:1:1: lights: no lights"] * 2


def test_warnings_as_errors_stop_the_load():
    with warnings.catch_warnings():
        warnings.simplefilter("error", rtcli.RtcliWarning)
        with pytest.raises(rtcli.RtcliWarning, match="no lights"):
            rtcli.load_scene(DARK)


# --- the camera check ---
def test_the_camera_check_proves_sight_without_tracing_when_it_can(monkeypatch):
    """An object wholly in view, or a floor seen, needs neither the BVH nor the scene's full trace."""
    traced = []
    monkeypatch.setattr("rtcli.wavefront.intersect.find_first_hit", lambda *a, **k: traced.append(1))
    monkeypatch.setattr("rtcli.rendering.engine.numpy_engine", lambda *a, **k: traced.append(1))
    ball = model(CLEAN)
    floor = model(CLEAN.replace("{sphere: {}", "{plane: {point: [0, -1, 0]}}, {sphere: {center: [0, 0, 9]}")
                 .replace("look_at: [0, 0, 0]", "look_at: [0, -1, -1]"))
    assert checks._camera_sees_something(ball) and checks._camera_sees_something(floor)
    assert traced == []


def test_an_object_wholly_in_view_between_the_signature_s_rays_is_seen():
    """A ball far smaller than a pixel of the 512-pixel signature: no ray hits it, but it is in view."""
    text = CLEAN.replace("image: {width: 32, height: 24}", "image: {width: 512, height: 512}")
    scene = rtcli.load_scene(text.replace("{sphere: {}", "{sphere: {center: [0.0147, 0.0147, 0], radius: 0.0006}"))
    assert scene.warnings == ()
    assert not checks._signature_hits(scene.model, 512)


@pytest.mark.parametrize("seed", range(3))
def test_wholly_in_view_is_only_said_of_objects_a_ray_from_the_eye_meets(seed):
    """Random balls and cameras: wherever the proof says a ball is wholly in view, the ray from the
    eye through its centre hits an object."""
    rng = np.random.default_rng(seed)
    balls = "".join(f"  - {{sphere: {{center: [{x:.3f}, {y:.3f}, {z:.3f}], radius: {r:.3f}}}}}\n"
                    for (x, y, z), r in zip(rng.uniform(-6, 6, (40, 3)), rng.uniform(0.05, 1.5, 40)))
    proven = 0
    for eye, look in zip(rng.uniform(-12, 12, (8, 3)), rng.uniform(-4, 4, (8, 3))):
        text = (f"image: {{width: 48, height: 32}}\ncamera: {{eye: {eye.round(3).tolist()}, "
                f"look_at: {look.round(3).tolist()}, fov: {rng.uniform(10, 90):.1f}}}\nobjects:\n" + balls)
        scene = model(text)
        s = scene.settings
        cam = scene.camera(s.width, s.height)
        for k, o in enumerate(scene.objects):
            single = _alone(scene, k)
            if checks._wholly_in_view(single, cam):
                proven += 1
                centre = np.mean(o.bounds(), axis=0)
                ray = Rays(cam.eye[:, None], (centre - cam.eye)[:, None])
                with np.errstate(all="ignore"):
                    assert np.isfinite(find_first_hit(scene, ray).t[0])
    assert proven > 0


def model(text: str):
    """The engines' scene of YAML text, built without looking for warnings."""
    return scene_from_yaml(text)


def _alone(scene, k: int):
    """A copy of the scene whose only object is its k-th."""
    import copy
    single = copy.copy(scene)
    single.__dict__.pop("boxes", None)
    single.objects = [scene.objects[k]]
    return single


# --- counts ---
def test_counts_say_1_thing_and_2_things():
    from rtcli.errors import plural
    from rtcli.inspect.views import summary
    assert [plural(n, "warning") for n in (0, 1, 2)] == ["0 warnings", "1 warning", "2 warnings"]
    assert plural(1, "mesh", "meshes") + ", " + plural(3, "mesh", "meshes") == "1 mesh, 3 meshes"
    assert summary(np.array([[np.inf, 2.0]]), "depth").endswith("; 1 pixel misses (black)")
    assert summary(np.array([[np.inf, np.inf, 2.0]]), "depth").endswith("; 2 pixels miss (black)")
    assert summary(np.array([[np.inf]]), "depth") == "depth: every ray misses (1 pixel black)"
    a = np.zeros((4, 4, 3), np.uint8)
    b = a.copy()
    b[1, 2] = 9
    assert rtcli.diff(a, b).summary.startswith("OK: 1 bad pixel (limit 16), ")
    b[2, 2] = 9
    assert rtcli.diff(a, b).summary.startswith("OK: 2 bad pixels (limit 16), ")


def test_validate_s_summary_counts_in_singular_or_plural(run, tmp_path):
    (tmp_path / "one.yaml").write_text("animation: {frames: 1}\n" + CLEAN.replace(
        "eye: [0, 0, 5]", "eye: {keys: {0: [0, 0, 5]}}"))
    assert run("validate", "one.yaml").stdout == (
        "one.yaml: ok: 1 object (1 sphere), 1 light, 1 material; 32x24, max_depth 5, phong, samples 1; "
        "animated: 1 frame at 24 fps (0..0.0416667 s), 1 keyframed value\n")


def test_strict_with_keep_going_leaves_out_the_scenes_with_warnings(run, tmp_path):
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "a.yaml").write_text(SCENE)
    (tmp_path / "scenes" / "b.yaml").write_text(CLEAN)
    result = run("render", "scenes", "-o", "out", "--keep-going", "--strict")
    assert result.exit_code == 2
    assert result.stderr.splitlines()[0].startswith("error: scenes/a.yaml:4:44: objects[0].material.diffuse: ")
    assert sorted(os.listdir(tmp_path / "out")) == ["b.png"]
