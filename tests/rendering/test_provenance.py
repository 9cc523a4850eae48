"""Every image says how it was made (README.md, Images): the provenance in PNG, TIFF, JPEG, WebP and
EXR files, `rtcli info`, and `rtcli compare` on EXR and PFM, with its notes when two images were
made with other settings or another rtcli."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import OpenEXR
import pytest
from click.testing import CliRunner
from PIL import Image

import rtcli
from rtcli.cli import main
from rtcli.rendering import provenance

SCENE = """\
image: {width: 20, height: 16}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects:
  - {name: ball, sphere: {radius: 1}, material: {diffuse: [0.9, 0.2, 0.1]}}
  - {name: cube, box: {min: [1.2, -0.5, -0.5], max: [1.8, 0.5, 0.5]}, material: {diffuse: [0.2, 0.8, 0.3]}}
"""


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE)
    runner = CliRunner()
    return lambda *args: runner.invoke(main, [*args] + (["--workers", "1"] if args[0] == "render" else []))


def expected_meta(tmp_path, **changes) -> dict:
    values = {"version": rtcli.__version__, "sources": provenance.sources_digest(), "scene": "s.yaml",
              "scene_sha256": hashlib.sha256((tmp_path / "s.yaml").read_bytes()).hexdigest(), "frame": "1",
              "size": "20x16", "samples": "1", "max_depth": "5", "block_size": "1", "gamma": "false",
              "alpha": "false", "content": "color", "engine": "numpy", **changes}
    return {f"rtcli.{k}": v for k, v in values.items()}


def without_time(meta: dict) -> dict:
    assert float(meta.pop("rtcli.render_seconds")) >= 0
    return meta


def test_a_png_holds_its_provenance_as_text_chunks(run, tmp_path):
    assert run("render", "s.yaml", "-o", "x.png", "--samples", "2", "--max-depth", "3", "--engine", "numpy",
               "--gamma").exit_code == 0
    with Image.open(tmp_path / "x.png") as img:
        assert without_time(dict(img.text)) == expected_meta(tmp_path, samples="2", max_depth="3", gamma="true")
    assert len(provenance.sources_digest()) == 64


@pytest.mark.parametrize("name", ["x.tif", "x.jpg", "x.webp", "x16.tif"])
def test_tiff_jpeg_and_webp_hold_it_as_json_in_their_description(run, tmp_path, name):
    extra = ["--bit-depth", "16"] if name == "x16.tif" else []
    assert run("render", "s.yaml", "-o", name, "--engine", "numpy", *extra).exit_code == 0
    with Image.open(tmp_path / name) as img:
        text = img.tag_v2[270] if img.format == "TIFF" else img.getexif()[270]
    assert without_time(json.loads(text)) == expected_meta(tmp_path)


def test_an_exr_holds_it_as_header_attributes(run, tmp_path):
    assert run("render", "s.yaml", "-o", "x.exr", "--engine", "numpy", "--layers", "ids").exit_code == 0
    with OpenEXR.File(str(tmp_path / "x.exr"), header_only=True) as f:
        header = {k: v for k, v in f.header().items() if k.startswith("rtcli.")}
    assert without_time(header) == expected_meta(tmp_path)


def test_views_and_signatures_say_what_they_hold(run, tmp_path):
    assert run("render", "s.yaml", "--view", "depth", "-o", "d.png").exit_code == 0
    assert run("signature", "s.yaml", "--ids", "ids.png", "-o", "sig.png", "--workers", "1").exit_code == 0
    assert Image.open(tmp_path / "d.png").text["rtcli.content"] == "view depth"
    assert Image.open(tmp_path / "ids.png").text["rtcli.content"] == "ids"
    assert Image.open(tmp_path / "sig.png").text["rtcli.scene"] == "s.yaml"


def test_info_prints_the_provenance_of_each_image(run, tmp_path):
    assert run("render", "s.yaml", "-o", "x.exr", "--alpha", "--layers", "depth").exit_code == 0
    assert run("render", "s.yaml", "-o", "x.png", "--samples", "3").exit_code == 0
    result = run("info", "x.exr", "x.png")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0] == "x.exr:" and lines[1] == "file            EXR 20x16, channels R G B A depth.T"
    assert "samples         3" in lines and "alpha           true" in lines
    digest = hashlib.sha256((tmp_path / "s.yaml").read_bytes()).hexdigest()
    assert lines.count(f"scene_sha256    {digest}") == 2
    found = [json.loads(line) for line in run("info", "--json", "x.png").output.splitlines()]
    assert found[0]["samples"] == "3" and found[0]["format"] == "PNG" and found[0]["size"] == "20x16"


def test_info_exits_1_for_an_image_without_provenance_and_2_for_a_bad_file(run, tmp_path):
    Image.new("RGB", (3, 2)).save(tmp_path / "other.png")
    assert run("render", "s.yaml", "-o", "x.bmp").exit_code == 0
    result = run("info", "other.png")
    assert result.exit_code == 1 and "(no rtcli provenance" in result.output
    assert run("info", "x.bmp").exit_code == 1                        # BMP has no place for it
    (tmp_path / "bad.png").write_bytes(b"not an image")
    result = run("info", "bad.png")
    assert result.exit_code == 2 and result.output.startswith("error: bad.png: not a readable image")
    assert run("info", "gone.png").output == "error: gone.png: no such file\n"


def test_compare_notes_other_settings_and_another_rtcli(run, tmp_path):
    assert run("render", "s.yaml", "-o", "a.png").exit_code == 0
    assert run("render", "s.yaml", "-o", "b.png").exit_code == 0
    assert run("render", "s.yaml", "-o", "c.png", "--max-depth", "2").exit_code == 0
    same = run("compare", "a.png", "b.png")
    assert same.exit_code == 0 and same.output.count("\n") == 1 and "note" not in same.output
    other = run("compare", "a.png", "c.png")
    assert other.output.splitlines()[1] == "note: made with different settings: max_depth 5 (actual) vs 2"
    meta = dict(Image.open(tmp_path / "b.png").text, **{"rtcli.version": "0.0.9"})
    pixels = np.asarray(Image.open(tmp_path / "b.png"))
    rtcli.ImageArray(pixels, meta=meta).save(str(tmp_path / "old.png"))
    older = run("compare", "a.png", "old.png")
    assert older.exit_code == 0
    assert older.output.splitlines()[1] == f"note: made with different rtcli: version {rtcli.__version__} (actual) vs 0.0.9"


def test_compare_reads_exr_and_pfm_with_a_tolerance_in_linear_floats(run, tmp_path):
    assert run("render", "s.yaml", "-o", "a.exr", "--layers", "ids").exit_code == 0
    assert run("render", "s.yaml", "-o", "a.pfm").exit_code == 0
    with OpenEXR.File(str(tmp_path / "a.exr"), separate_channels=True) as f:
        header = dict(f.header())
        channels = {k: np.array(c.pixels) for k, c in f.channels().items()}
    channels["R"][3, 4] += 0.02                                       # one pixel beyond 0.01, one within
    channels["G"][5, 5] += 0.005
    OpenEXR.File({k: v for k, v in header.items() if k.startswith("rtcli.")}, channels).write(str(tmp_path / "b.exr"))
    result = run("compare", "b.exr", "a.exr", "--max-bad-pixels", "0", "--diff", "d.png")
    assert result.exit_code == 1
    assert result.output.startswith("FAIL: 1 bad pixel (limit 0), largest cluster 1 px at (x=4, y=3), max error 0.02")
    assert "id layer: 0 mismatched ids" in result.output
    heat = np.asarray(Image.open(tmp_path / "d.png"))
    assert heat[3, 4].tolist() == [255, 129, 0] and heat[5, 5].tolist() == [120, 0, 0] and not heat[0, 0].any()
    assert run("compare", "b.exr", "a.exr", "--max-bad-pixels", "0", "--float-tolerance", "0.03").exit_code == 0
    result = run("compare", "a.pfm", "a.exr")
    assert result.exit_code == 0 and result.output.startswith("OK: 0 bad pixels")
    assert "note: only the expected image says how it was made" in result.output
    assert run("compare", "a.pfm", "a.exr", "--flip", "f.png").output.startswith("error: --flip compares 8-bit")


def test_compare_uses_the_id_layer_of_two_exrs(run, tmp_path):
    assert run("render", "s.yaml", "-o", "a.exr", "--layers", "ids").exit_code == 0
    (tmp_path / "t.yaml").write_text(SCENE.replace("min: [1.2,", "min: [0.6,"))
    assert run("render", "t.yaml", "-o", "b.exr", "--layers", "ids").exit_code == 0
    result = run("compare", "b.exr", "a.exr", "--ids", "--max-boundary-mismatch", "0")
    assert result.exit_code == 1 and result.output.startswith("FAIL: ") and "mismatched ids" in result.output
    assert "note: made with different settings: scene_sha256" in result.output
    assert run("compare", "a.exr", "a.exr", "--ids").output.startswith("OK: 0 mismatched ids")


def test_folders_of_exr_images_are_compared_and_the_report_shows_the_notes(run, tmp_path):
    (tmp_path / "actual").mkdir()
    (tmp_path / "golden").mkdir()
    assert run("render", "s.yaml", "-o", "actual/x.exr").exit_code == 0
    assert run("render", "s.yaml", "-o", "golden/x.exr", "--samples", "2").exit_code == 0
    result = run("compare", "actual", "golden", "--report", "report")
    lines = result.output.splitlines()
    assert lines[0].startswith("x.exr: ") and lines[1] == "  note: made with different settings: samples 1 " \
                                                           "(actual) vs 2"
    page = (tmp_path / "report" / "index.html").read_text()
    assert '<div class="note">note: made with different settings: samples 1 (actual) vs 2</div>' in page
    assert Image.open(tmp_path / "report" / "images" / "0001-actual.png").size == (20, 16)


@pytest.mark.parametrize("name", ["m.apng", "m.gif"])
def test_frames_and_movies_carry_it_too(run, tmp_path, name):
    (tmp_path / "anim.yaml").write_text(SCENE.replace("image:", "animation: {frames: 3, fps: 12}\nimage:")
                                        .replace("eye: [0, 0, 5]", "eye: {keys: {0: [0, 0, 5], 0.2: [0, 1, 5]}}"))
    assert run("render", "anim.yaml", "-o", "f_%d.png", "--movie", name).exit_code == 0
    assert Image.open(tmp_path / "f_2.png").text["rtcli.frame"] == "2"
    result = run("info", name)
    assert result.exit_code == 0 and "frame           1-3" in result.output.splitlines()


def test_broken_float_files_are_one_line_errors(run, tmp_path):
    assert run("render", "s.yaml", "-o", "a.pfm").exit_code == 0
    (tmp_path / "bad.exr").write_bytes(b"v/1\x01" + b"\0" * 40)
    (tmp_path / "cut.pfm").write_bytes((tmp_path / "a.pfm").read_bytes()[:-7])
    (tmp_path / "huge.pfm").write_bytes(b"PF\n100000 100000\n-1.0\n" + b"\0" * 64)
    (tmp_path / "text.pfm").write_bytes(b"P6\n2 2\n255\n" + b"\0" * 12)
    for args, message in [(["bad.exr", "bad.exr"], "bad.exr: not a readable EXR"),
                          (["cut.pfm", "a.pfm"], "cut.pfm: a PFM of 20x16 should hold 3,840 bytes of pixels, not 3,833"),
                          (["huge.pfm", "a.pfm"], "huge.pfm: 100000x100000 is 10,000,000,000 pixels, more than"),
                          (["text.pfm", "a.pfm"], "text.pfm: not a PFM file")]:
        result = run("compare", *args)
        assert result.exit_code == 2 and result.output.startswith(f"error: {message}"), result.output
        assert result.output.count("\n") == 1
    assert run("info", "bad.exr").output.startswith("error: bad.exr: not a readable EXR")
