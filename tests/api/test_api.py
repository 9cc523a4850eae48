"""The Python API: scenes from paths, YAML text and dicts; renders to arrays, Pillow images and files."""

from __future__ import annotations

import io
import subprocess
import sys
import warnings

import numpy as np
import pytest
import yaml
from PIL import Image

import rtcli
from rtcli.core.display import to_8bit

SCENE = """\
image: {width: 32, height: 24}
camera: {eye: [0, 1, 5], look_at: [0, 0.5, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects:
  - {name: floor, plane: {point: [0, 0, 0], normal: [0, 1, 0]}, material: {diffuse: 0.8}}
  - {name: ball, sphere: {center: [0, 0.8, 0], radius: 0.8}, material: {preset: copper, reflection: 0.3}}
"""


@pytest.fixture
def spec():
    return yaml.safe_load(SCENE)


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(SCENE)
    return path


def test_a_path_yaml_text_and_a_dict_render_the_same_pixels(scene_file, spec):
    images = [rtcli.render(source, workers=1) for source in (str(scene_file), scene_file, SCENE, spec)]
    assert images[0].shape == (24, 32, 3) and images[0].dtype == np.uint8
    for image in images[1:]:
        assert np.array_equal(image, images[0])


def test_dict_errors_are_located_by_key_path(spec):
    spec["objects"][1]["sphere"]["radius"] = -1
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(spec)
    assert str(e.value) == "<dict>: objects[1].sphere.radius: must be > 0, got -1"
    spec["objects"][1]["sphere"] = {"raduis": 1}
    with pytest.raises(rtcli.SceneError, match=r"^<dict>: objects\[1\]\.sphere\.raduis: unknown key "
                                               r"\(did you mean 'radius'\?\); allowed here: center, radius$"):
        rtcli.load_scene(spec)


@pytest.mark.parametrize("value, message", [
    (object(), "<dict>: objects[0].name: must be a dict, list, string, number, boolean or None, "
               "got a value of type object"),
    ({(1, 2): 3}, "<dict>: objects[0].name: keys must be strings, got a key of type tuple"),
])
def test_dict_values_that_yaml_cannot_hold_are_refused(spec, value, message):
    spec["objects"][0]["name"] = value
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(spec)
    assert str(e.value) == message


def test_a_dict_that_contains_itself_is_refused(spec):
    spec["objects"].append(spec["objects"])
    with pytest.raises(rtcli.SceneError, match=r"^<dict>: objects\[2\]: contains itself"):
        rtcli.load_scene(spec)


def test_numpy_values_tuples_and_paths_are_plain_values(spec, tmp_path):
    spec["objects"][1]["sphere"]["center"] = np.array([0, 0.8, 0])
    spec["objects"][1]["sphere"]["radius"] = np.float32(0.8)
    spec["camera"]["eye"] = (0, 1, 5)
    assert np.array_equal(rtcli.render(spec, workers=1), rtcli.render(SCENE, workers=1))
    (tmp_path / "m.yaml").write_text("materials: {red: {diffuse: [1, 0, 0]}}\n")
    spec["include"] = ["m.yaml"]
    spec["objects"][0]["material"] = "red"
    scene = rtcli.load_scene(spec, folder=tmp_path)
    assert scene.inputs == (str((tmp_path / "m.yaml").resolve()),)


def test_yaml_text_errors_name_the_string_with_line_and_column():
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(SCENE.replace("fov: 40", "fov: 400"))
    assert str(e.value) == "<string>:2:53: camera.fov: must be between 0 and 180 degrees, got 400"


def test_overrides_keep_the_command_lines_rules(spec):
    scene = rtcli.load_scene(spec, width=64)
    assert (scene.width, scene.height) == (64, 48)                     # one side keeps the aspect ratio
    image = rtcli.render(scene, height=12, samples=2, workers=1)
    assert image.shape == (12, 16, 3) and image.stats.primary == 12 * 16 * 4
    assert scene.model.settings.samples == 1                           # a render's override is its own
    with pytest.raises(rtcli.RtcliError, match=r"^samples must be an integer in 1\.\.16, got 17$"):
        rtcli.render(scene, samples=17)
    with pytest.raises(TypeError):
        rtcli.render(scene, sample=2)


def test_a_stretched_window_camera_is_a_warning():
    text = SCENE.replace("fov: 40", "window: {left: -1, right: 1, top: 0.75, bottom: -0.75}")
    with pytest.warns(UserWarning, match="the window camera keeps its rectangle"):
        rtcli.render(text, width=10, height=10, workers=1)


def test_linear_colors_convert_to_the_8bit_image_exactly(spec):
    image = rtcli.render(spec, workers=1, samples=2)
    linear = rtcli.render(spec, workers=1, samples=2, linear=True)
    assert linear.dtype == np.float64 and linear.shape == image.shape
    assert np.array_equal(to_8bit(np.asarray(linear)), image)
    assert np.array_equal(linear.to_8bit(gamma=True), rtcli.render(spec, workers=1, samples=2, gamma=True))
    with pytest.raises(rtcli.RtcliError, match="gamma encodes 8-bit images"):
        rtcli.render(spec, linear=True, gamma=True)


def test_images_show_in_jupyter_convert_to_pillow_and_keep_stats(spec):
    image = rtcli.render(spec, workers=1, engine="numpy")
    shown = Image.open(io.BytesIO(image._repr_png_()))
    assert np.array_equal(np.asarray(shown.convert("RGB")), image)
    assert image.to_pil().mode == "RGB" and image.to_pil().size == (32, 24)
    stats = image.stats
    assert isinstance(stats, rtcli.RenderStats) and stats.engine == "numpy"
    assert stats.total == stats.primary + stats.shadow + stats.reflected + stats.refracted > 32 * 24
    assert set(stats.as_dict()) >= {"primary", "shadow", "reflected", "refracted", "total", "seconds"}
    assert image[:2].stats is None and (image[:2, :2, 0]._repr_png_() is None)


def test_a_scene_shows_a_small_preview():
    scene = rtcli.load_scene(SCENE, width=640)
    preview = Image.open(io.BytesIO(scene._repr_png_()))
    assert preview.size == (192, 144)
    assert "2 objects (1 plane, 1 sphere)" in repr(scene)


def test_saving_refuses_the_scenes_own_files_and_writes_through_the_writer(scene_file, tmp_path):
    image = rtcli.render(scene_file, workers=1)
    with pytest.raises(rtcli.RtcliError, match="is an input of this run"):
        image.save(scene_file)
    with pytest.raises(rtcli.RtcliError, match="the output format follows the extension"):
        rtcli.render(scene_file, output=tmp_path / "x.txt")
    image.save(tmp_path / "a.jpg")
    assert Image.open(tmp_path / "a.jpg").format == "JPEG"
    assert scene_file.read_text() == SCENE


def test_signature_ids_are_an_array_with_a_legend(spec):
    scene = rtcli.load_scene(spec)
    ids = rtcli.signature(scene, workers=1)
    assert ids.dtype == np.uint16 and ids.shape == (24, 32)
    assert set(np.unique(ids)) == {0, 1, 2}
    rows = rtcli.legend(scene, ids)
    assert [(r.id, r.name, r.shape) for r in rows] == [(0, "(background)", "-"), (1, "floor", "plane"),
                                                       (2, "ball", "sphere")]
    assert sum(r.pixels for r in rows) == 32 * 24
    assert Image.open(io.BytesIO(ids._repr_png_())).mode == "RGB"


def test_diff_passes_equal_images_and_fails_a_changed_material(spec):
    before = rtcli.render(spec, workers=1)
    assert rtcli.diff(before, before.copy()).ok
    spec["objects"][1]["material"] = {"preset": "gold"}
    d = rtcli.diff(rtcli.render(spec, workers=1), before)
    assert not d.ok and d.summary.startswith("FAIL: ") and d.comparison.bad_pixels > 16
    assert d.heat_map.shape == before.shape and d._repr_png_()
    with pytest.raises(TypeError, match="unknown options: tolerence"):
        rtcli.diff(before, before, tolerence=3)


def test_import_rtcli_is_cheap_and_render_stays_the_function():
    code = ("import sys, rtcli; cheap = 'numpy' not in sys.modules; from rtcli.rendering.tiles import Job; "
            "import rtcli.rendering.tiles; print(cheap, callable(rtcli.render) and rtcli.render.__module__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["True", "rtcli.api"]


def test_no_warning_for_an_ordinary_render(spec):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rtcli.render(spec, width=16, workers=1)


ANIMATED = SCENE.replace("image:", "animation: {fps: 4, frames: 5}\nimage:").replace(
    "radius: 0.8}", "radius: 0.8}, transform: [{translate: {keys: {0: [-1, 0, 0], 1: [1, 0, 0]}}}]").replace(
    "lights: [{position: [5, 5, 5]}]", "lights: [{position: {keys: {0: [5, 5, 5], 1: [-5, 5, 5]}}}]")


def test_a_frame_of_an_animated_scene_is_the_command_lines_frame(tmp_path, monkeypatch):
    """load_scene(frame=k), render(frame=k) and Scene.at(k) give the bytes of `rtcli render --frame k`."""
    from click.testing import CliRunner

    from rtcli.cli import main
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.yaml").write_text(ANIMATED)
    assert CliRunner().invoke(main, ["render", "a.yaml", "--frame", "3", "-o", "cli.png", "--width", "16",
                                     "--workers", "1"]).exit_code == 0
    cli = np.asarray(Image.open(tmp_path / "cli.png"))
    scene = rtcli.load_scene("a.yaml", width=16)
    assert (scene.frame, scene.frames, scene.fps) == (1, 5, 4.0) and "frame 1 of 5" in repr(scene)
    third = scene.at(3)
    assert (third.frame, third.width, third.height, scene.at(1) is scene) == (3, 16, 12, True)
    for image in (rtcli.render(third, workers=1), rtcli.render(scene, frame=3, workers=1),
                  rtcli.render("a.yaml", frame=3, width=16, workers=1),
                  rtcli.render(rtcli.load_scene(ANIMATED, frame=3, width=16), workers=1),
                  rtcli.render(yaml.safe_load(ANIMATED), frame=3, width=16, workers=1)):
        assert np.array_equal(image, cli)
    assert not np.array_equal(rtcli.render(scene, workers=1), cli)
    assert rtcli.signature(scene, frame=3).shape == (12, 16)
    still = rtcli.load_scene(SCENE)
    assert (still.frame, still.frames, still.fps, still.at(1) is still) == (1, 1, None, True)


@pytest.mark.parametrize("source, frame, message", [
    (ANIMATED, 6, "frame 6: <string> has 5 frames (1-5)"),
    (ANIMATED, 0, "frame must be an integer in 1..100000, got 0"),
    (ANIMATED, "2", "frame must be an integer in 1..100000, got '2'"),
    (SCENE, 2, "frame 2: <string> is a still (one frame)"),
])
def test_a_frame_the_scene_does_not_have_is_refused(source, frame, message):
    with pytest.raises(rtcli.RtcliError) as e:
        rtcli.load_scene(source, frame=frame)
    assert str(e.value) == message
    with pytest.raises(rtcli.RtcliError) as e:
        rtcli.load_scene(source).at(frame)
    assert str(e.value) == message
