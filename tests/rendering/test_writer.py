"""PNG output: 8-bit conversion, deterministic bytes, atomic writes, 16-bit ids, the palette."""

from __future__ import annotations

import colorsys

import numpy as np
import pytest
from PIL import Image

from rtcli.core.display import palette, srgb_encode, to_8bit
from rtcli.errors import RtcliError
from rtcli.rendering.writer import write_png


def test_to_8bit_clamps_and_rounds():
    """Pixels are clamp(c, 0, 1) then round(255 c)."""
    c = np.array([[[-0.5, 0.0, 0.5], [1 / 255 * 0.49, 1 / 255 * 0.51, 7.0]]])
    np.testing.assert_array_equal(to_8bit(c), [[[0, 0, 128], [0, 1, 255]]])


def test_gamma_is_the_srgb_curve():
    """--gamma: linear 0.5 becomes 188, as POV-Ray's default output."""
    assert to_8bit(np.array([[[0.5, 0.0, 1.0]]]), gamma=True).tolist() == [[[188, 0, 255]]]
    assert srgb_encode(np.array(0.001)) == pytest.approx(0.01292)


def test_same_pixels_same_bytes(tmp_path):
    """No timestamps or metadata: the same image always gives the same file."""
    img = np.random.default_rng(1).integers(0, 256, (30, 40, 3), dtype=np.uint8)
    write_png(str(tmp_path / "a.png"), img)
    write_png(str(tmp_path / "b.png"), img)
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_output_has_ordinary_permissions(tmp_path):
    """The atomically written file gets the umask's permissions, not the temp file's 0600."""
    import os
    old = os.umask(0o022)
    try:
        write_png(str(tmp_path / "a.png"), np.zeros((2, 2, 3), np.uint8))
    finally:
        os.umask(old)
    assert (tmp_path / "a.png").stat().st_mode & 0o777 == 0o644


def test_ids_round_trip_16_bit(tmp_path):
    """Signature ids are stored exactly as 16-bit gray."""
    ids = np.array([[0, 1, 2], [300, 65535, 7]], dtype=np.uint16)
    write_png(str(tmp_path / "ids.png"), ids)
    back = Image.open(tmp_path / "ids.png")
    assert back.mode == "I;16"
    np.testing.assert_array_equal(np.asarray(back), ids)


def test_failed_write_leaves_nothing(tmp_path, monkeypatch):
    """An error while writing leaves neither the target nor a temporary file."""
    (tmp_path / "out.png").write_bytes(b"old")

    def boom(*args, **kwargs):
        raise OSError("disk full")
    monkeypatch.setattr(Image.Image, "save", boom)
    with pytest.raises(RtcliError, match="cannot write"):
        write_png(str(tmp_path / "out.png"), np.zeros((2, 2, 3), np.uint8))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png"]
    assert (tmp_path / "out.png").read_bytes() == b"old"


def test_palette_is_fixed_black_background_and_neighbours_differ():
    """Id 0 is black; each id's color never changes; ids k and k+1 are far apart in color."""
    p = palette(200).astype(float)
    assert p[0].tolist() == [0, 0, 0]
    np.testing.assert_array_equal(palette(10), palette(200)[:11])
    assert len({tuple(c) for c in p}) == len(p)
    gaps = np.abs(np.diff(p[1:], axis=0)).sum(axis=1)
    assert gaps.min() > 100, gaps.min()
    hues = np.array([colorsys.rgb_to_hsv(*(c / 255))[0] for c in p[1:]])
    hue_gap = np.abs(np.diff(hues))
    assert np.minimum(hue_gap, 1 - hue_gap).min() > 0.2
