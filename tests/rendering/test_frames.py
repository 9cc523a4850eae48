"""rtcli render on animations: frame files, one frame, movies, resuming, and the errors.

The rule the tests pin: every frame's file is byte for byte the file of that frame
rendered alone, whatever else the command rendered and with how many workers.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import same_image
from PIL import Image

from rtcli.cli import main

ORBIT = Path(__file__).resolve().parents[2] / "scenes" / "orbit.yaml"
SMALL = ["--width", "40", "--height", "30"]


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copy(ORBIT, tmp_path / "orbit.yaml")
    runner = CliRunner()
    return lambda *args: runner.invoke(main, list(args))


def test_each_frame_of_a_sequence_is_the_frame_rendered_alone(run, tmp_path):
    result = run("render", "orbit.yaml", "--frames", "3-7", "-o", "out_%03d.png", "--workers", "2", *SMALL)
    assert result.exit_code == 0, result.output
    assert sorted(os.listdir(tmp_path)) == ["orbit.yaml"] + [f"out_{k:03d}.png" for k in range(3, 8)]
    for k in (3, 5, 7):
        assert run("render", "orbit.yaml", "--frame", str(k), "-o", "alone.png", "--workers", "1",
                   *SMALL).exit_code == 0
        assert same_image(tmp_path / "alone.png", tmp_path / f"out_{k:03d}.png"), k
    frames = [np.asarray(Image.open(tmp_path / f"out_{k:03d}.png")) for k in range(3, 8)]
    assert all(np.any(a != b) for a, b in zip(frames, frames[1:]))          # the camera moves


def test_a_movie_holds_the_frames(run, tmp_path):
    result = run("render", "orbit.yaml", "--frames", "1-4", "-o", "f%d.png", "--movie", "m.apng", *SMALL)
    assert result.exit_code == 0, result.output
    with Image.open(tmp_path / "m.apng") as movie:
        assert (movie.format, movie.n_frames, movie.info.get("loop")) == ("PNG", 4, 0)
        for k in range(4):
            movie.seek(k)
            assert np.array_equal(np.asarray(movie.convert("RGB")), np.asarray(Image.open(tmp_path / f"f{k + 1}.png")))
    assert run("render", "orbit.yaml", "-o", "all.gif", *SMALL).exit_code == 0
    with Image.open(tmp_path / "all.gif") as gif:
        assert (gif.format, gif.n_frames) == ("GIF", 24)
    assert sorted(os.listdir(tmp_path)) == ["all.gif", "f1.png", "f2.png", "f3.png", "f4.png", "m.apng", "orbit.yaml"]


def durations(path) -> list[int]:
    """The delay of each frame of an animated image, in ms, as read back by Pillow."""
    with Image.open(path) as movie:
        found = []
        for k in range(movie.n_frames):
            movie.seek(k)
            found.append(movie.info["duration"])
        return found


def test_a_movie_keeps_its_frame_rate(run, tmp_path):
    """orbit.yaml is 24 frames at 12 fps, 2 s: a GIF's delays, whole hundredths, alternate 80 and 90 ms
    (83.3 on average), an APNG's 83 and 84 ms; both last 2 s."""
    assert run("render", "orbit.yaml", "-o", "o.gif", "--movie", "o.apng", *SMALL).exit_code == 0
    gif, apng = durations(tmp_path / "o.gif"), durations(tmp_path / "o.apng")
    assert gif[:6] == [80, 90, 80, 80, 90, 80] and sum(gif) == 2000 and len(gif) == 24
    assert set(apng) == {83, 84} and sum(apng) == 2000
    for k in range(1, 25):                          # each frame starts within half a tick of (k - 1) / 12 s
        assert abs(sum(gif[:k]) - k * 1000 / 12) <= 5 and abs(sum(apng[:k]) - k * 1000 / 12) <= 0.5


def test_skip_existing_renders_only_the_missing_frames(run, tmp_path):
    assert run("render", "orbit.yaml", "--frames", "1-3", "-o", "f%d.png", *SMALL).exit_code == 0
    first = (tmp_path / "f1.png").read_bytes()
    os.unlink(tmp_path / "f2.png")
    os.utime(tmp_path / "f3.png", (0, 0))
    result = run("render", "orbit.yaml", "--frames", "1-3", "-o", "f%d.png", "--skip-existing",
                 "--movie", "m.apng", *SMALL)
    assert result.exit_code == 0, result.output
    assert os.stat(tmp_path / "f3.png").st_mtime == 0 and (tmp_path / "f1.png").read_bytes() == first
    assert (tmp_path / "f2.png").exists()
    with Image.open(tmp_path / "m.apng") as movie:
        movie.seek(2)
        assert np.array_equal(np.asarray(movie.convert("RGB")), np.asarray(Image.open(tmp_path / "f3.png")))


def test_a_still_render_of_an_animated_scene_is_frame_1(run, tmp_path):
    assert run("render", "orbit.yaml", "-o", "still.png", *SMALL).exit_code == 0
    assert run("render", "orbit.yaml", "--frame", "1", "-o", "one.png", *SMALL).exit_code == 0
    assert same_image(tmp_path / "still.png", tmp_path / "one.png")


def test_validate_checks_every_frame(run):
    result = run("validate", "orbit.yaml")
    assert result.exit_code == 0
    assert result.output.endswith("; animated: 24 frames at 12 fps (0..2 s), 3 keyframed values\n")


def test_validate_says_its_warnings_are_about_frame_1(run, tmp_path):
    text = (tmp_path / "orbit.yaml").read_text()
    (tmp_path / "bytes.yaml").write_text(text.replace("color: [0.45, 0.45, 0.45]", "color: [255, 255, 255]"))
    result = run("validate", "bytes.yaml")
    assert result.exit_code == 0 and "warning: [255, 255, 255] looks like 0-255 values" in result.stderr
    assert result.stderr.endswith("note: the warnings are about frame 1 of 24 (the camera, lights and objects "
                                  "where the animation starts)\n")
    assert "note:" not in run("validate", "orbit.yaml").stderr


@pytest.mark.parametrize("args, message", [
    (["--frames", "1-30", "-o", "f%d.png"], "--frames 1-30: orbit.yaml has 24 frames (1-24)"),
    (["--frames", "5-2", "-o", "f%d.png"], "--frames 5-2: give a range FIRST-LAST of frame numbers, from 1 (e.g. 1-24)"),
    (["--frame", "25"], "--frame 25: orbit.yaml has 24 frames (1-24)"),
    (["--frames", "1-2", "--frame", "2", "-o", "f%d.png"], "--frames and --frame: give one"),
    (["--frames", "1-2", "-o", "f.png"], "-o f.png: 2 frames need a name with the frame number (frame_%04d.png) "
                                         "or a movie (.apng, .gif)"),
    (["-o", "f%d%s.png"], "-o f%d%s.png: a frame pattern has one %d (or %04d ..., a width below 100) for the "
                          "frame number, and %% for a percent sign"),
    (["-o", "f.png", "--movie", "m.mp4"], "m.mp4: an animation is written as an animated PNG or GIF: '.mp4' is "
                                          "not one of .apng, .gif"),
    (["-o", "orbit.yaml", "--frame", "2"], "orbit.yaml: is an input of this run; it will not be overwritten "
                                          "(choose another output name)"),
    (["--frames", "1-2", "-o", "g_%02d.gif"], "-o g_%02d.gif: a movie is one file, so its name takes no frame "
                                              "number; for one image a frame, name them .png (frame_%04d.png)"),
    (["--frames", "1-2", "-o", "new/f_%02d.png", "--frame", "1"], "--frames and --frame: give one"),
])
def test_frame_option_errors_are_one_line_and_write_nothing(run, tmp_path, args, message):
    result = run("render", "orbit.yaml", *args, *SMALL)
    assert (result.exit_code, result.output) == (2, f"error: {message}\n")
    assert os.listdir(tmp_path) == ["orbit.yaml"]


def test_an_error_in_a_later_frame_stops_before_any_file_is_written(run, tmp_path):
    (tmp_path / "bad.yaml").write_text(
        "animation: {frames: 4}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
        "objects: [{sphere: {}, transform: [{scale: {keys: {0: 1, 0.125: 0}}}]}]\nlights: [{position: [0, 0, 5]}]\n")
    result = run("render", "bad.yaml", "-o", "f%d.png", *SMALL)
    assert (result.exit_code, result.output) == (
        2, "error: bad.yaml:3:65: objects[0].transform[0].scale: singular transform (determinant 0) "
           "(at frame 4, time 0.125 s)\n")
    assert sorted(os.listdir(tmp_path)) == ["bad.yaml", "orbit.yaml"]


def test_skip_existing_with_every_frame_written_renders_nothing_and_reaches_no_cluster(run, tmp_path):
    assert run("render", "orbit.yaml", "--frames", "1-2", "-o", "f%d.png", *SMALL).exit_code == 0
    before = {p: os.stat(tmp_path / p).st_mtime_ns for p in ("f1.png", "f2.png")}
    result = run("render", "orbit.yaml", "--frames", "1-2", "-o", "f%d.png", "--skip-existing", "--movie", "m.gif",
                 "--cluster", "tcp://127.0.0.1:1", *SMALL)         # nothing listens there: never asked
    assert (result.exit_code, result.output) == (0, "")
    assert {p: os.stat(tmp_path / p).st_mtime_ns for p in ("f1.png", "f2.png")} == before
    with Image.open(tmp_path / "m.gif") as movie:
        assert movie.n_frames == 2


# --- frames beside the other ways to render: several scenes, views, explain, statistics ---
@pytest.mark.parametrize("args", [
    ["--frames", "1-2"],
    ["--movie", "m.gif"],
    ["-o", "all.gif"],
])
def test_frame_sequences_of_several_scenes_are_a_usage_error(run, tmp_path, args):
    shutil.copy(ORBIT, tmp_path / "other.yaml")
    result = run("render", "orbit.yaml", "other.yaml", *args, *SMALL)
    assert (result.exit_code, result.output) == (2, "error: --frames and movies render one animated scene, not "
                                                    "several (--frame N renders frame N of each)\n")
    assert sorted(os.listdir(tmp_path)) == ["orbit.yaml", "other.yaml"]


def test_frame_n_of_several_scenes_is_each_scene_s_frame_n(run, tmp_path):
    shutil.copy(ORBIT, tmp_path / "other.yaml")
    result = run("render", "orbit.yaml", "other.yaml", "--frame", "6", "-o", "out", "--stats", "--json", *SMALL)
    assert result.exit_code == 0, result.output
    assert [json.loads(line)["output"] for line in result.output.splitlines()] == ["out/orbit.png", "out/other.png"]
    assert run("render", "orbit.yaml", "--frame", "6", "-o", "six.png", *SMALL).exit_code == 0
    for name in ("orbit", "other"):
        assert same_image(tmp_path / "out" / f"{name}.png", tmp_path / "six.png", ignore=("scene",))
    (tmp_path / "still.yaml").write_text("camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n")
    result = run("render", "orbit.yaml", "still.yaml", "--frame", "2", "-o", "out2", *SMALL)
    assert (result.exit_code, result.output) == (2, "error: --frame 2: still.yaml is a still (one frame)\n")
    assert not (tmp_path / "out2").exists()


def test_skip_existing_with_several_scenes_renders_only_the_missing_images(run, tmp_path):
    shutil.copy(ORBIT, tmp_path / "other.yaml")
    shutil.copy(ORBIT, tmp_path / "third.yaml")
    (tmp_path / "out").mkdir()
    Image.new("RGB", (40, 30), "red").save(tmp_path / "out" / "orbit.png")        # the size asked for: kept
    kept = (tmp_path / "out" / "orbit.png").read_bytes()
    Image.new("RGB", (20, 15), "red").save(tmp_path / "out" / "third.png")        # another size: rendered again
    result = run("render", "orbit.yaml", "other.yaml", "third.yaml", "-o", "out", "--skip-existing", "--stats",
                 *SMALL)
    assert result.exit_code == 0, result.output
    assert [line.split(":")[0] for line in result.output.splitlines()] == ["other.yaml", "third.yaml"]
    assert (tmp_path / "out" / "orbit.png").read_bytes() == kept
    assert Image.open(tmp_path / "out" / "other.png").size == (40, 30)
    assert same_image(tmp_path / "out" / "third.png", tmp_path / "out" / "other.png", ignore=("scene",))
    (tmp_path / "out" / "other.png").write_bytes(b"not an image")                  # rendered again too
    result = run("render", "orbit.yaml", "other.yaml", "third.yaml", "-o", "out", "--skip-existing", "--stats",
                 "--height", "15")
    assert [line.split(":")[0] for line in result.output.splitlines()] == ["orbit.yaml", "other.yaml", "third.yaml"]
    assert Image.open(tmp_path / "out" / "orbit.png").size == (20, 15)


def test_skip_existing_renders_again_a_frame_of_another_size(run, tmp_path):
    """A run resumed at another size must not mix sizes: frames of the old size are rendered again."""
    assert run("render", "orbit.yaml", "--frames", "1-3", "-o", "f%d.png", "--width", "20").exit_code == 0
    assert run("render", "orbit.yaml", "--frames", "2-2", "-o", "f%d.png", *SMALL).exit_code == 0
    before = os.stat(tmp_path / "f2.png").st_mtime_ns
    result = run("render", "orbit.yaml", "--frames", "1-3", "-o", "f%d.png", "--skip-existing", "--movie", "m.gif",
                 "--stats", "--json", *SMALL)
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["frames"] == [1, 3]
    assert os.stat(tmp_path / "f2.png").st_mtime_ns == before
    assert [Image.open(tmp_path / f"f{k}.png").size for k in (1, 2, 3)] == [(40, 30)] * 3
    assert durations(tmp_path / "m.gif") and Image.open(tmp_path / "m.gif").size == (40, 30)


def test_a_view_and_an_explanation_take_the_frame(run, tmp_path):
    import rtcli
    for k in (1, 5):
        assert run("render", "orbit.yaml", "--frame", str(k), "-o", f"f{k}.png", *SMALL).exit_code == 0
        assert run("render", "orbit.yaml", "--frame", str(k), "--view", "depth", "-o", f"d{k}.png",
                   *SMALL).exit_code == 0
    f1, f5 = (np.asarray(Image.open(tmp_path / f"f{k}.png")) for k in (1, 5))
    view = rtcli.view(rtcli.load_scene("orbit.yaml", frame=5), "depth", width=40)
    assert np.array_equal(np.asarray(Image.open(tmp_path / "d5.png")), view.to_8bit())
    assert (tmp_path / "d1.png").read_bytes() != (tmp_path / "d5.png").read_bytes()
    y, x = np.argwhere(np.any(f1 != f5, axis=2))[0]
    result = run("explain", "orbit.yaml", str(x), str(y), "--frame", "5", "--json", *SMALL)
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["byte"] == f5[y, x].tolist()
    result = run("explain", "orbit.yaml", "1", "1", "--frame", "25")
    assert (result.exit_code, result.output) == (2, "error: --frame 25: orbit.yaml has 24 frames (1-24)\n")


@pytest.mark.parametrize("args, message", [
    (["--view", "normal", "--frames", "1-2"], "--view writes one picture: give --frame N, not --frames, a frame "
                                              "pattern or a movie"),
    (["--view", "normal", "-o", "n%d.png"], "--view writes one picture: give --frame N, not --frames, a frame "
                                            "pattern or a movie"),
    (["--view", "normal", "--local-cluster", "2"], "--view is computed on this machine: it takes no cluster option"),
])
def test_views_of_several_frames_or_on_a_cluster_are_usage_errors(run, tmp_path, args, message):
    result = run("render", "orbit.yaml", *args, *SMALL)
    assert (result.exit_code, result.output) == (2, f"error: {message}\n")
    assert os.listdir(tmp_path) == ["orbit.yaml"]


def test_stats_of_a_sequence_count_the_frames_rendered(run, tmp_path):
    result = run("render", "orbit.yaml", "--frames", "2-4", "-o", "f%d.png", "--stats", "--json", *SMALL)
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert (data["scene"], data["frames"], data["primary"], data["width"]) == ("orbit.yaml", [2, 3, 4], 3 * 1200, 40)
    os.unlink(tmp_path / "f3.png")
    result = run("render", "orbit.yaml", "--frames", "2-4", "-o", "f%d.png", "--stats", "--json", "--skip-existing",
                 *SMALL)
    assert (json.loads(result.output)["frames"], json.loads(result.output)["primary"]) == ([3], 1200)
    result = run("render", "orbit.yaml", "--frames", "2-4", "-o", "f%d.png", "--stats", *SMALL)
    assert result.output.startswith("rays: 3600 primary, ") and result.output.count("\n") == 1


def test_a_frame_pattern_makes_its_folder(run, tmp_path):
    """-o out/frame_%04d.png in a folder that does not exist yet makes it (its parent must exist)."""
    result = run("render", "orbit.yaml", "--frames", "1-2", "-o", "out/f_%02d.png", *SMALL)
    assert result.exit_code == 0, result.output
    assert sorted(os.listdir(tmp_path / "out")) == ["f_01.png", "f_02.png"]
    result = run("render", "orbit.yaml", "--frames", "1-2", "-o", "no/deeper/f_%02d.png", *SMALL)
    assert result.exit_code == 2 and "cannot create the output folder" in result.output
