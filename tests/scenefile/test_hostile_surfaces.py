"""Hostile input on the newer surfaces: animation clocks and movies, --cluster-file, NUL bytes in paths.

Every case keeps the rule of tests/scenefile/test_hostile_input.py: one `error:` line, exit 2,
no partial output file, in bounded time and memory.
"""

from __future__ import annotations

import os
import struct
import zlib

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from rtcli.cli import main
from rtcli.rendering import movie
from rtcli.rendering.frames import _read_back
from rtcli.rendering.tiles import Job

SCENE = """\
camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
image: {width: 8, height: 6}
lights: [{position: [5, 5, 5]}]
objects: [{sphere: {}}]
"""


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("RTCLI_NUMBA", "0")
    runner = CliRunner()
    return lambda *args: runner.invoke(main, list(args))


def one_error(result) -> str:
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error: ") and result.output.count("\n") == 1, result.output
    return result.output[len("error: "):-1]


def animated(tmp_path, section: str, name: str = "a.yaml") -> str:
    (tmp_path / name).write_text(SCENE + f"animation: {section}\n")
    return name


def png_header(path, width: int, height: int, rows: int = 1) -> None:
    """A PNG that says it is width x height, with `rows` rows of data (a decompression bomb's header)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    head = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    data = zlib.compress(b"\0" * (width * 3 + 1) * rows, 9)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", data) + chunk(b"IEND", b""))


# --- animation clocks ---
@pytest.mark.parametrize("section", ["{clock: [0, 1e-12]}", "{fps: 1e-20, clock: [0, 5]}", "{fps: 24, clock: [3, 3.01]}"])
def test_a_clock_shorter_than_a_frame_has_one_frame_at_its_start(run, tmp_path, section):
    name = animated(tmp_path, section)
    result = run("render", name, "-o", "f_%d.png")
    assert result.exit_code == 0, result.output
    assert sorted(os.listdir(tmp_path)) == [name, "f_1.png"]
    assert run("validate", name).output.count("animated: 1 frame at ") == 1


@pytest.mark.parametrize("section, where", [("{fps: 1e-20, frames: 2}", "5:18"), ("{fps: 5e-324, frames: 3}", "5:18"),
                                            ("{frames: 100000, fps: 1e-16}", "5:34")])
def test_frame_times_beyond_the_numbers_a_scene_holds_are_refused(run, tmp_path, section, where):
    message = one_error(run("render", animated(tmp_path, section), "-o", "f_%d.png"))
    assert message.startswith(f"a.yaml:{where}: animation.fps: ") and "more than the 1e+20 s a clock may span" in message
    assert sorted(os.listdir(tmp_path)) == ["a.yaml"]


@pytest.mark.parametrize("pattern", ["f_%0100d.png", "f_%999999999999d.png"])
def test_a_frame_number_as_wide_as_memory_is_refused(run, tmp_path, pattern):
    """`output % k` would build a name of a trillion characters (or one no folder can hold)."""
    message = one_error(run("render", animated(tmp_path, "{fps: 4, frames: 2}"), "-o", pattern))
    assert message.startswith(f"-o {pattern}: a frame pattern has one %d (or %04d ..., a width below 100)")
    assert sorted(os.listdir(tmp_path)) == ["a.yaml"]


# --- movies ---
@pytest.mark.parametrize("ext, longest", [(".gif", "655.35"), (".apng", "65.535")])
@pytest.mark.parametrize("fps", ["1e-20", "0.001"])
def test_a_movie_frame_longer_than_its_format_holds_is_refused_before_rendering(run, tmp_path, ext, longest, fps):
    name = animated(tmp_path, f"{{fps: {fps}, clock: [0, 3000]}}" if fps == "0.001" else f"{{fps: {fps}, clock: [0, 1]}}")
    message = one_error(run("render", name, "-o", "m" + ext))
    assert message.startswith(f"-o m{ext}: at {float(fps):g} fps a frame lasts ")
    assert f"longer than the {longest} s a frame of" in message
    assert sorted(os.listdir(tmp_path)) == [name]


def test_a_slow_movie_within_its_formats_delays_is_written(tmp_path):
    frames = [np.zeros((2, 2, 3), np.uint8), np.ones((2, 2, 3), np.uint8)]
    for ext in ("apng", "gif"):
        movie.check_rate(f"m.{ext}", 2, 0.02)                              # 50 s a frame
        movie.write_movie(str(tmp_path / f"m.{ext}"), frames, 0.02)
        with Image.open(tmp_path / f"m.{ext}") as m:
            assert (m.n_frames, m.info["duration"]) == (2, 50000)


def test_a_gif_of_identical_frames_longer_than_a_gif_frame_is_refused(tmp_path):
    frames = [np.zeros((2, 2, 3), np.uint8)] * 700                   # 700 s at 1 fps, one picture
    with pytest.raises(movie.RtcliError, match=r"^-o .*m\.gif: frames 1-656 are the same picture, which a GIF "):
        movie.write_movie(str(tmp_path / "m.gif"), frames, 1.0)
    assert os.listdir(tmp_path) == []
    frames[300] = np.ones((2, 2, 3), np.uint8)                          # 300 s, 1 s, 399 s: a GIF holds it
    movie.write_movie(str(tmp_path / "m.gif"), frames, 1.0)
    with Image.open(tmp_path / "m.gif") as m:
        assert m.n_frames == 3
    movie.write_movie(str(tmp_path / "m.apng"), [frames[0]] * 700, 1.0)    # an APNG splits the run


def test_skip_existing_never_decodes_a_bomb_among_the_earlier_frames(run, tmp_path):
    name = animated(tmp_path, "{fps: 4, frames: 3}")
    png_header(tmp_path / "f_1.png", 100_000, 100_000)                # 10^10 pixels said, 370 bytes
    png_header(tmp_path / "f_2.png", 12_000, 10_000)                  # Pillow's warning zone
    result = run("render", name, "-o", "f_%d.png", "--movie", "m.gif", "--skip-existing")
    assert result.exit_code == 0 and result.output == "", result.output
    for k in (1, 2, 3):                                               # of another size: rendered again
        with Image.open(tmp_path / f"f_{k}.png") as img:
            assert img.size == (8, 6)


def test_an_earlier_frame_read_back_is_checked_from_its_header(tmp_path):
    threshold = Image.MAX_IMAGE_PIXELS
    png_header(tmp_path / "f.png", 100_000, 100_000)
    with pytest.raises(movie.RtcliError, match=r"f\.png: an earlier frame larger than 8x6: render it again"):
        _read_back(str(tmp_path / "f.png"), Job(8, 6))
    png_header(tmp_path / "f.png", 8, 5, rows=5)
    with pytest.raises(movie.RtcliError, match=r"f\.png: an earlier frame of 8x5, not 8x6"):
        _read_back(str(tmp_path / "f.png"), Job(8, 6))
    png_header(tmp_path / "f.png", 8, 6, rows=6)
    assert _read_back(str(tmp_path / "f.png"), Job(8, 6)).shape == (6, 8, 3)
    assert Image.MAX_IMAGE_PIXELS == threshold                                   # put back


# --- --cluster-file ---
def cluster_file_error(run, tmp_path, path) -> str:
    (tmp_path / "s.yaml").write_text(SCENE)
    message = one_error(run("render", "s.yaml", "--cluster-file", str(path), "-o", "out.png"))
    assert not (tmp_path / "out.png").exists()
    return message.replace(str(tmp_path) + "/", "")


@pytest.mark.parametrize("make, reason", [
    (lambda p: os.mkfifo(p), "sched.json: not a regular file but a FIFO (named pipe)"),
    (lambda p: os.mkdir(p), "sched.json: not a regular file but a folder"),
    (lambda p: p.write_text(" " * 65537), "sched.json: too large for a scheduler file: 65,537 bytes, more than the 65,536 allowed"),
    (lambda p: p.write_text("[" * 60000), "sched.json: not a Dask scheduler file: its JSON nests too deep"),
    (lambda p: p.write_text('{"address":\n  tcp}'), "sched.json: not a Dask scheduler file (Expecting value: line 2 column 3 (char 14))"),
    (lambda p: p.write_bytes(b'{"address": "\xff"}'), "sched.json: not a Dask scheduler file: byte 13 is not UTF-8"),
    (lambda p: p.write_text('["tcp://127.0.0.1:8786"]'), 'sched.json: names no scheduler address (a JSON object with "address")'),
])
def test_a_cluster_file_is_a_small_regular_json_file(run, tmp_path, make, reason):
    make(tmp_path / "sched.json")
    assert cluster_file_error(run, tmp_path, tmp_path / "sched.json") == f"--cluster-file {reason}"


def test_a_cluster_file_that_is_a_device_is_never_read(run, tmp_path):
    message = cluster_file_error(run, tmp_path, "/dev/zero")
    assert message == "--cluster-file /dev/zero: not a regular file but a character device"


def test_a_cluster_file_gives_its_address(tmp_path):
    from rtcli.cluster.schedulerfile import scheduler_address
    (tmp_path / "s.json").write_text('{"type": "Scheduler", "address": "tcp://127.0.0.1:8786", "workers": {}}')
    assert scheduler_address(str(tmp_path / "s.json")) == "tcp://127.0.0.1:8786"


# --- folder comparison: names of any bytes ---
def test_report_and_junit_show_names_that_are_not_utf8(run, tmp_path):
    import xml.etree.ElementTree as ET
    actual, expected = os.fsencode(tmp_path / "act\udcff"), os.fsencode(tmp_path / "exp\n")
    for folder, shade in ((actual, 0), (expected, 50)):
        os.mkdir(folder)
        Image.fromarray(np.full((4, 4, 3), shade, np.uint8)).save(folder + b"/x\xff\xfe<b>.png")
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(expected + b"/gold\x80\".png")
    result = run("compare", os.fsdecode(actual), os.fsdecode(expected), "--report", "rep", "--junit", "j.xml")
    assert result.exit_code == 1, result.output
    lines = result.output.replace(str(tmp_path), "T").splitlines()
    assert lines == ["'gold\\x80\".png': MISSING: no actual image for 'T/exp\\n/gold\\x80\".png'",
                     "'x\\xff\\xfe<b>.png': FAIL: 16 bad pixels (limit 16), largest cluster 16 px at (x=0, y=0), "
                     "max error 50/255 at (x=0, y=0), mean error 50.00/255",
                     "FAIL: 2 pairs: 0 ok, 1 failing, 1 missing, 0 extra, 0 unreadable"]
    page = (tmp_path / "rep" / "index.html").read_text(encoding="utf-8")
    assert '<div class="path">x\\xff\\xfe&lt;b&gt;.png</div>' in page
    assert '<div class="path">gold\\x80&quot;.png</div>' in page and "act\\xff against " in page
    assert "exp\\n" in page and "<b>" not in page
    names = [case.get("name") for case in ET.parse(tmp_path / "j.xml").iter("testcase")]
    assert names == ['gold\\x80".png', "x\\xff\\xfe<b>.png"]


# --- OBJ numbers beyond a scene's ---
@pytest.mark.parametrize("line, message", [("v 1e300 0 0", "m.obj:2:3: number 1e300 in 'v' must be between -1e20 and 1e20"),
                                           ("vn 0 -2e20 0", "m.obj:2:6: number -2e20 in 'vn' must be between -1e20 and 1e20")])
def test_an_obj_number_beyond_a_scenes_is_one_line_without_numpys_warnings(tmp_path, line, message):
    """Whichever reader reads the file (the bulk one here), the careful one names the number; no
    RuntimeWarning of numpy on stderr. A subprocess, so stderr is all rtcli printed."""
    import subprocess
    import sys
    (tmp_path / "m.obj").write_text(f"v 0 0 0\n{line}\nv 1e20 1 0\nv 0 1 0\nf 1 3 4\n")
    (tmp_path / "s.yaml").write_text(SCENE.replace("{sphere: {}}", "{mesh: {file: m.obj}}"))
    done = subprocess.run([sys.executable, "-m", "rtcli", "render", "s.yaml", "-o", "out.png"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120, env={**os.environ, "RTCLI_NUMBA": "0"})
    assert (done.returncode, done.stdout, done.stderr) == (2, "", f"error: {message}\n")
    assert not (tmp_path / "out.png").exists()
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1e20 0 0\nv 0 1e20 0\nf 1 2 3\n")          # at the limit: renders
    assert subprocess.run([sys.executable, "-m", "rtcli", "render", "s.yaml", "-o", "out.png"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120, env={**os.environ, "RTCLI_NUMBA": "0"}).stderr == ""
