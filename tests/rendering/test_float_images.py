"""Float and 16-bit images, alpha and layers (README.md, Images): each format written by rtcli and
read back by an independent reader (the OpenEXR package, numpy for PFM, pypng and Pillow for
16-bit PNG, the TIFF's strip read by numpy), and the combinations refused."""

from __future__ import annotations

import struct

import numpy as np
import OpenEXR
import png
import pytest
from click.testing import CliRunner
from PIL import Image

import rtcli
from rtcli.cli import main
from rtcli.core.display import to_8bit, to_16bit
from rtcli.kernels import variants

SCENE = """\
image: {width: 24, height: 18}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
background: [0.2, 0.3, 0.4]
lights: [{position: [5, 5, 5], color: [3.0, 3.0, 3.0]}]
objects:
  - {name: ball, sphere: {radius: 1}, material: {diffuse: [0.9, 0.2, 0.1], specular: 0.8, shininess: 20}}
  - {name: cube, box: {min: [1.2, -0.5, -0.5], max: [1.8, 0.5, 0.5]}, material: {diffuse: [0.2, 0.8, 0.3]}}
"""


@pytest.fixture
def run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.yaml").write_text(SCENE)
    (tmp_path / "a.yaml").write_text(SCENE.replace("image:", "render: {alpha: true, samples: 2}\nimage:"))
    runner = CliRunner()
    return lambda *args: runner.invoke(main, [*args, "--workers", "1", "--engine", "numpy"])


@pytest.fixture(scope="module")
def linear():
    """The scene's linear radiance, as the API renders it (float64, unclamped)."""
    return np.asarray(rtcli.render(SCENE, linear=True, workers=1, engine="numpy"))


def exr_channels(path) -> dict:
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {name: np.array(c.pixels) for name, c in f.channels().items()}


def test_an_exr_holds_the_linear_radiance_as_float32_and_half_as_float16(run, tmp_path, linear):
    assert linear.max() > 1                                       # radiance past 1: clamping would lose it
    assert run("render", "s.yaml", "-o", "x.exr").exit_code == 0
    channels = exr_channels(tmp_path / "x.exr")
    assert sorted(channels) == ["B", "G", "R"]
    assert all(c.dtype == np.float32 for c in channels.values())
    assert np.array_equal(np.stack([channels[c] for c in "RGB"], axis=2), linear.astype(np.float32))
    assert run("render", "s.yaml", "-o", "h.exr", "--half").exit_code == 0
    half = exr_channels(tmp_path / "h.exr")
    assert half["R"].dtype == np.float16 and np.array_equal(half["R"], linear[..., 0].astype(np.float16))


def test_a_pfm_holds_the_linear_radiance_bottom_row_first(run, tmp_path, linear):
    assert run("render", "s.yaml", "-o", "x.pfm").exit_code == 0
    data = (tmp_path / "x.pfm").read_bytes()
    assert data.startswith(b"PF\n24 18\n-1.0\n")
    values = np.frombuffer(data[len(b"PF\n24 18\n-1.0\n"):], dtype="<f4").reshape(18, 24, 3)
    assert np.array_equal(values[::-1], linear.astype(np.float32))


def test_a_16_bit_png_reads_back_with_pypng_and_pillow(run, tmp_path, linear):
    assert run("render", "s.yaml", "-o", "x.png", "--bit-depth", "16", "--gamma").exit_code == 0
    width, height, rows, info = png.Reader(filename=str(tmp_path / "x.png")).read()
    assert (width, height, info["bitdepth"], info["planes"]) == (24, 18, 16, 3)
    pixels = np.vstack([np.asarray(row, dtype=np.uint16) for row in rows]).reshape(18, 24, 3)
    expected = to_16bit(linear, gamma=True)
    assert np.array_equal(pixels, expected)
    with Image.open(tmp_path / "x.png") as img:               # Pillow reads it too, as 8 bits (the high bytes)
        assert img.mode == "RGB" and np.array_equal(np.asarray(img), (expected >> 8).astype(np.uint8))
        assert img.text["rtcli.gamma"] == "true"
    assert len(np.unique(pixels)) > len(np.unique(pixels >> 8))          # finer steps than 8 bits


def test_a_16_bit_tiff_holds_the_same_values(run, tmp_path, linear):
    assert run("render", "s.yaml", "-o", "x.tif", "--bit-depth", "16").exit_code == 0
    with Image.open(tmp_path / "x.tif") as img:
        tags = img.tag_v2
        assert (img.size, tags[258], tags[259], tags[262]) == ((24, 18), (16, 16, 16), 1, 2)
        start, count = tags[273][0], tags[279][0]
        assert '"rtcli.size": "24x18"' in tags[270] and tags[305] == f"rtcli {rtcli.__version__}"
    data = (tmp_path / "x.tif").read_bytes()
    assert data[:4] == b"II*\0" and struct.unpack("<I", data[4:8])[0] % 2 == 0
    pixels = np.frombuffer(data[start:start + count], dtype="<u2").reshape(18, 24, 3)
    assert np.array_equal(pixels, to_16bit(linear))


def test_the_8_bit_png_is_the_linear_render_converted(run, tmp_path, linear):
    assert run("render", "s.yaml", "-o", "x.png").exit_code == 0
    assert np.array_equal(np.asarray(Image.open(tmp_path / "x.png")), to_8bit(linear))


def test_alpha_makes_the_background_transparent_in_png_and_exr(run, tmp_path):
    assert run("render", "a.yaml", "-o", "a.png").exit_code == 0
    assert run("render", "s.yaml", "--samples", "2", "--alpha", "-o", "flag.png").exit_code == 0
    assert run("render", "s.yaml", "--samples", "2", "-o", "plain.png").exit_code == 0
    rgba, plain = np.asarray(Image.open(tmp_path / "a.png")), np.asarray(Image.open(tmp_path / "plain.png"))
    assert rgba.shape == (18, 24, 4) and np.array_equal(rgba, np.asarray(Image.open(tmp_path / "flag.png")))
    alpha = rgba[..., 3]
    assert alpha[0, 0] == 0 and alpha[9, 12] == 255                 # the sky; the ball's middle
    edge = (alpha > 0) & (alpha < 255)
    assert edge.any()                                               # some samples of a pixel hit, some do not
    assert np.array_equal(rgba[alpha == 255][:, :3], plain[alpha == 255])     # covered: the same colors
    assert not rgba[alpha == 0][:, :3].any()                        # no background color left
    assert run("render", "a.yaml", "-o", "a.exr").exit_code == 0
    channels = exr_channels(tmp_path / "a.exr")
    a = channels["A"]
    assert np.array_equal(np.rint(a * 255).astype(np.uint8), alpha)
    assert not channels["R"][a == 0].any()                            # premultiplied: 0 where A is 0
    straight = rtcli.render(tmp_path / "a.yaml", linear=True, workers=1)
    assert straight.shape == (18, 24, 4)
    assert np.array_equal(channels["G"], (straight[..., 1] * straight[..., 3]).astype(np.float32))


def test_alpha_is_the_same_with_the_compiled_engine():
    if not variants.ENABLED:
        pytest.skip("numba is not installed")
    scene = SCENE.replace("image:", "render: {alpha: true, samples: 2}\nimage:")
    a = rtcli.render(scene, linear=True, workers=1, engine="numpy")
    b = rtcli.render(scene, linear=True, workers=1, engine="compiled")
    assert b.stats.engine == "compiled" and np.array_equal(a, b)


def test_layers_hold_the_views_with_mitsuba_s_channel_names(run, tmp_path):
    result = run("render", "s.yaml", "-o", "x.exr", "--layers", "normal,depth,uv,albedo,bounces,ids")
    assert result.exit_code == 0, result.output
    channels = exr_channels(tmp_path / "x.exr")
    assert sorted(channels) == sorted(["R", "G", "B", "normal.X", "normal.Y", "normal.Z", "depth.T", "uv.U", "uv.V",
                                       "albedo.R", "albedo.G", "albedo.B", "bounces.Y", "ids.Y"])
    scene = rtcli.load_scene(tmp_path / "s.yaml")
    normal, depth, uv = (rtcli.view(scene, k) for k in ("normal", "depth", "uv"))
    assert np.array_equal(np.stack([channels[f"normal.{c}"] for c in "XYZ"], 2), normal.astype(np.float32))
    assert np.array_equal(channels["depth.T"], depth.astype(np.float32)) and np.isinf(channels["depth.T"][0, 0])
    assert np.array_equal(channels["uv.U"], np.where(np.isfinite(uv[..., 0]), uv[..., 0], 0).astype(np.float32))
    assert np.array_equal(channels["bounces.Y"], rtcli.view(scene, "bounces").astype(np.float32))
    ids = channels["ids.Y"]
    assert ids.dtype == np.uint32 and np.array_equal(ids, rtcli.signature(scene, workers=1))
    assert set(np.unique(ids)) == {0, 1, 2}


@pytest.mark.parametrize("args, message", [
    (["-o", "x.jpg", "--alpha"], "x.jpg: alpha (render: {alpha: true} or --alpha) needs a format with an alpha"),
    (["-o", "x.bmp", "--scene-alpha"], "x.bmp: alpha (render: {alpha: true} or --alpha) needs"),
    (["-o", "x.pfm", "--alpha"], "x.pfm: alpha"),
    (["-o", "x.png", "--half"], "x.png: float16 (--half) is for EXR"),
    (["-o", "x.png", "--layers", "depth"], "x.png: layers go into a multi-layer EXR"),
    (["-o", "x.jpg", "--bit-depth", "16"], "x.jpg: 16 bits a channel go to .png or .tif"),
    (["-o", "x.exr", "--bit-depth", "16"], "x.exr: 16 bits a channel go to .png or .tif"),
    (["-o", "x.exr", "--gamma"], "x.exr: EXR and PFM hold the linear radiance"),
    (["-o", "x.exr", "--layers", "depth,shadows"], "Invalid value for '--layers': no layer 'shadows'"),
    (["--view", "depth", "--layers", "depth"], "--view writes an 8-bit picture"),
])
def test_formats_refuse_what_they_cannot_hold_before_rendering(run, tmp_path, args, message):
    scene = "a.yaml" if "--scene-alpha" in args else "s.yaml"
    result = run("render", scene, *[a for a in args if a != "--scene-alpha"])
    assert result.exit_code == 2 and result.output.startswith(f"error: {message}"), result.output
    assert result.output.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.yaml", "s.yaml"]


def test_the_api_writes_the_same_files(tmp_path, linear):
    image = rtcli.render(SCENE, output=tmp_path / "api.exr", workers=1, layers=["ids"])
    assert image.dtype == np.float64 and set(image.layers) == {"ids"}
    channels = exr_channels(tmp_path / "api.exr")
    assert np.array_equal(channels["R"], linear[..., 0].astype(np.float32))
    assert image.meta["rtcli.content"] == "color" and image.meta["rtcli.scene"] == "<string>"
    with pytest.raises(rtcli.RtcliError, match="16 bits a channel go to .png or .tif"):
        rtcli.render(SCENE, output=tmp_path / "x.jpg", bit_depth=16)
    assert not (tmp_path / "x.jpg").exists()
