"""The golden-image gate fails on real rendering bugs and passes on noise."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rtcli.compare.images import (
    compare,
    compare_ids,
    compare_images,
    heat_map,
    id_boundary,
    read_png,
)
from rtcli.errors import RtcliError

H, W = 150, 200
DISCS = [(60, 70, 30), (140, 80, 35)]          # (cx, cy, radius)


def scene(discs=DISCS, flip=()):
    """A 200x150 picture: smooth background gradient, a soft floor shadow, shaded discs.

    Each disc's brightness grows along x; discs listed in `flip` have it mirrored
    (the look of a flipped normal).  Disc edges are sharp.
    """
    y, x = np.mgrid[0:H, 0:W].astype(float)
    img = np.stack([40 + 0.5 * x, 60 + 0.6 * y, 90 + 0.3 * (x + y)], axis=-1)
    img[(x - 100) ** 2 / 80 ** 2 + (y - 130) ** 2 / 10 ** 2 < 1] *= 0.5
    for i, (cx, cy, r) in enumerate(discs):
        inside = (x - cx) ** 2 + (y - cy) ** 2 < r * r
        u = (x - cx) / r * (-1 if i in flip else 1)
        shade = 140 + 100 * u
        img[inside] = np.stack([shade, 0.8 * shade, 0.5 * shade], axis=-1)[inside]
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def ids_scene(shift=0):
    """An id map: background 0, a rectangle 1, two discs 2 and 3."""
    y, x = np.mgrid[0:H, 0:W]
    ids = np.zeros((H, W), np.uint16)
    ids[20:60, 120:180] = 1
    ids[(x - 60 - shift) ** 2 + (y - 70) ** 2 < 30 ** 2] = 2
    ids[(x - 140) ** 2 + (y - 100) ** 2 < 25 ** 2] = 3
    return ids


def darker(img, mask, levels):
    out = img.astype(int)
    out[mask] -= levels
    return np.clip(out, 0, 255).astype(np.uint8)


# --- the color gate passes -------------------------------------------------

def test_identical_images_pass():
    img = scene()
    c = compare_images(img, img.copy())
    assert c.ok and c.bad_pixels == 0 and c.largest_cluster == 0 and c.limit == 16
    assert c.summary == ("OK: 0 bad pixels (limit 16), largest cluster 0 px, "
                         "max error 0/255, mean error 0.00/255")


def test_one_level_noise_passes():
    img = scene()
    noise = np.random.default_rng(1).integers(-1, 2, img.shape)
    c = compare_images(np.clip(img + noise, 0, 255).astype(np.uint8), img)
    assert c.ok and c.bad_pixels == 0 and c.max_error == 1
    assert 0.3 < c.mean_error < 0.8


def test_tolerance_is_two_levels():
    img = scene()
    assert compare_images(darker(img, np.s_[10:12, 10:12], 2), img).ok
    c = compare_images(darker(img, np.s_[10:12, 10:12], 3), img)
    assert not c.ok and c.bad_pixels == 4


# --- the color gate fails on rendering bugs --------------------------------

def test_shadow_band_fails():
    img = scene()
    band = np.zeros((H, W), bool)
    band[100, 20:60] = True
    c = compare_images(darker(img, band, 30), img)
    assert not c.ok
    assert c.bad_pixels == 40 and c.largest_cluster == 40 and c.cluster_at == (20, 100)
    assert c.max_error == 30


def test_flipped_normal_fails():
    c = compare_images(scene(flip=(1,)), scene())
    assert not c.ok and c.bad_pixels > 1000 and c.max_error > 150


def test_half_pixel_shift_fails():
    img = scene().astype(int)
    shifted = img.copy()
    shifted[:, 1:] = img[:, :-1]
    half = ((img + shifted + 1) // 2).astype(np.uint8)
    c = compare_images(half, img.astype(np.uint8))
    assert not c.ok and c.largest_cluster > 3
    # the smooth background alone would pass: only the sharp edges fail
    background = compare_images(half[:20], img[:20].astype(np.uint8))
    assert background.ok


def test_missing_object_fails():
    c = compare_images(scene(discs=DISCS[:1]), scene())
    assert not c.ok and c.largest_cluster > 3000


# --- the count limit and the cluster limit ----------------------------------

def isolated(n, shape=(H, W)):
    """A mask of n pixels, each at least 9 pixels from the next (no clusters)."""
    mask = np.zeros(shape, bool)
    ys, xs = np.mgrid[5:shape[0]:10, 5:shape[1]:10]
    mask[ys.ravel()[:n], xs.ravel()[:n]] = True
    return mask


def test_sixteen_isolated_bad_pixels_pass_seventeen_fail():
    img = scene()
    c = compare_images(darker(img, isolated(16), 50), img)
    assert c.ok and c.bad_pixels == 16 and c.largest_cluster == 1
    c = compare_images(darker(img, isolated(17), 50), img)
    assert not c.ok and c.bad_pixels == 17 and c.largest_cluster == 1
    assert c.summary.startswith("FAIL: 17 bad pixels (limit 16), largest cluster 1 px at (x=")


def test_limit_grows_with_the_image():
    img = np.full((480, 640, 3), 128, np.uint8)           # 0.01% of 307200 = 30.72
    c = compare_images(darker(img, isolated(30, (480, 640)), 9), img)
    assert c.ok and c.limit == 30
    assert not compare_images(darker(img, isolated(31, (480, 640)), 9), img).ok
    one = darker(img, isolated(1, (480, 640)), 9)
    assert not compare_images(one, img, max_bad_pixels=0, max_bad_fraction=0).ok


def test_small_cluster_fails_although_count_is_tiny():
    img = scene()
    c = compare_images(darker(img, np.s_[40:42, 100:102], 10), img)
    assert not c.ok and c.bad_pixels == 4 and c.largest_cluster == 4
    assert c.cluster_at == (100, 40)
    assert "largest cluster 4 px at (x=100, y=40)" in c.summary


def test_clusters_are_eight_connected_and_three_is_allowed():
    img = scene()
    diagonal = np.zeros((H, W), bool)
    diagonal[[10, 11, 12], [10, 11, 12]] = True
    assert compare_images(darker(img, diagonal, 10), img).ok
    diagonal[13, 13] = True
    c = compare_images(darker(img, diagonal, 10), img)
    assert not c.ok and c.largest_cluster == 4
    assert compare_images(darker(img, diagonal, 10), img, max_cluster=4).ok


def test_size_differs_fails_with_message():
    c = compare_images(np.zeros((480, 640, 3), np.uint8), np.zeros((240, 320, 3), np.uint8))
    assert not c.ok
    assert "size differs: actual 640x480, expected 320x240" in c.summary


def test_wrong_kind_of_array_is_an_error():
    with pytest.raises(RtcliError, match="not an RGB image"):
        compare_images(np.zeros((4, 4), np.uint8), np.zeros((4, 4), np.uint8))
    c = compare(np.zeros((4, 4, 3), np.uint8), np.zeros((4, 4), np.uint16))
    assert not c.ok and "kind differs" in c.summary


def test_summary_is_one_line():
    img = scene()
    results = [compare_images(img, img), compare_images(scene(flip=(0,)), img),
               compare_images(img[:10], img),
               compare_ids(ids_scene(), ids_scene()), compare_ids(ids_scene(1), ids_scene())]
    for c in results:
        assert "\n" not in c.summary and c.summary.startswith(("OK: ", "FAIL: "))
    fail = results[1].summary
    assert " bad pixels (limit 16), largest cluster " in fail and " mean error " in fail


# --- heat map ---------------------------------------------------------------

def test_heat_map():
    img = np.full((4, 5, 3), 100, np.uint8)
    other = img.copy()
    other[0, 1, 2] = 101                   # 1 level: visible
    other[0, 2, 0] = 102                   # 2 levels: within tolerance
    other[0, 3, 1] = 103                   # 3 levels: bad
    other[0, 4, :] = 0                     # 100 levels: white
    heat = heat_map(other, img)
    assert heat.dtype == np.uint8 and heat.shape == (4, 5, 3)
    assert (heat[1:] == 0).all() and (heat[0, 0] == 0).all()
    brightness = heat[0].astype(int).sum(axis=1)
    assert list(brightness) == sorted(brightness) and brightness[1] > 60
    assert brightness[3] - brightness[2] > 100              # bad pixels stand out
    assert tuple(heat[0, 4]) == (255, 255, 255)


# --- id mode ----------------------------------------------------------------

def test_identical_ids_pass():
    c = compare_ids(ids_scene(), ids_scene())
    assert c.ok and c.bad_pixels == 0 and c.boundary_pixels > 0
    assert compare(ids_scene(), ids_scene()).ok


def test_swapped_object_id_fails():
    expected = ids_scene()
    actual = expected.copy()
    actual[expected == 3] = 1
    c = compare_ids(actual, expected)
    assert not c.ok and c.off_boundary > 1000
    assert ": actual 1, expected 3" in c.summary and "first off-boundary at (x=" in c.summary


def jitter(expected, n):
    """Move n edge pixels by one pixel: each takes the id of its right-hand neighbour."""
    edge = np.zeros_like(expected, bool)
    edge[:, :-1] = expected[:, :-1] != expected[:, 1:]
    ys, xs = np.nonzero(edge)
    pick = np.random.default_rng(2).choice(len(ys), n, replace=False)
    actual = expected.copy()
    actual[ys[pick], xs[pick]] = expected[ys[pick], xs[pick] + 1]
    return actual


def test_boundary_jitter_passes_up_to_the_limit():
    expected = ids_scene()
    n_boundary = int(id_boundary(expected).sum())
    limit = max(8, n_boundary // 100)                   # 1% of 1264 boundary pixels: 12
    assert limit == 12
    c = compare_ids(jitter(expected, limit), expected)
    assert c.ok and c.bad_pixels == limit and c.off_boundary == 0 and c.limit == limit
    c = compare_ids(jitter(expected, limit + 1), expected)
    assert not c.ok and c.off_boundary == 0
    assert f"(0 off boundary, 13 on boundary, limit 12 of {n_boundary} boundary pixels)" in c.summary
    assert "first on-boundary at (x=" in c.summary


def test_boundary_limit_is_a_fraction_of_boundary_pixels():
    expected = ids_scene()
    n_boundary = int(id_boundary(expected).sum())
    c = compare_ids(jitter(expected, 20), expected, max_boundary_fraction=20 / n_boundary)
    assert c.ok and c.limit == 20 and c.boundary_pixels == n_boundary
    small = compare_ids(jitter(expected, 9), expected, max_boundary_fraction=0)
    assert not small.ok and small.limit == 8            # the floor of 8 applies


def test_single_off_boundary_mismatch_fails():
    expected = ids_scene()
    actual = expected.copy()
    actual[70, 60] = 3                     # the centre of disc 2
    c = compare_ids(actual, expected)
    assert not c.ok and c.bad_pixels == 1 and c.off_boundary == 1
    assert c.summary.startswith("FAIL: 1 mismatched id (1 off boundary, 0 on boundary, limit 12 of ")
    assert c.summary.endswith("first off-boundary at (x=60, y=70): actual 3, expected 2")


def test_boundary_is_of_the_expected_map():
    expected = np.zeros((10, 10), np.uint16)
    expected[4, 4] = 5
    b = id_boundary(expected)
    assert b.sum() == 9 and b[3:6, 3:6].all()
    actual = expected.copy()
    actual[2, 2] = 5                       # next to the boundary, but off it
    assert compare_ids(actual, expected).off_boundary == 1


def test_ids_size_differs():
    c = compare_ids(np.zeros((480, 640), np.uint16), np.zeros((240, 320), np.uint16))
    assert not c.ok and "size differs: actual 640x480, expected 320x240" in c.summary


# --- read_png ---------------------------------------------------------------

def test_read_png_rgb_round_trip(tmp_path):
    img = scene()
    Image.fromarray(img).save(tmp_path / "a.png")
    back = read_png(tmp_path / "a.png")
    assert back.dtype == np.uint8 and np.array_equal(back, img)


def test_read_png_rgba_and_palette_become_rgb(tmp_path):
    img = scene()
    rgba = np.dstack([img, np.full((H, W), 200, np.uint8)])
    Image.fromarray(rgba).save(tmp_path / "a.png")
    assert np.array_equal(read_png(tmp_path / "a.png"), img)
    Image.fromarray(img).convert("P").save(tmp_path / "p.png")
    assert read_png(tmp_path / "p.png").shape == (H, W, 3)


def test_read_png_16_bit_ids_round_trip(tmp_path):
    ids = ids_scene().astype(int) * 1000 + 7            # values above 255
    Image.fromarray(ids.astype(np.uint16)).save(tmp_path / "ids.png")
    back = read_png(tmp_path / "ids.png")
    assert back.shape == (H, W) and np.array_equal(back, ids)
    assert compare_ids(back, ids).ok


def test_read_png_8_bit_gray_is_2d(tmp_path):
    Image.fromarray(ids_scene().astype(np.uint8)).save(tmp_path / "ids8.png")
    assert np.array_equal(read_png(tmp_path / "ids8.png"), ids_scene())


def test_read_png_errors_name_the_file(tmp_path):
    missing = tmp_path / "nope.png"
    with pytest.raises(RtcliError, match="nope.png: no such file"):
        read_png(missing)
    junk = tmp_path / "junk.png"
    junk.write_text("not a png\n")
    with pytest.raises(RtcliError, match="junk.png: not a readable PNG") as info:
        read_png(junk)
    assert "\n" not in str(info.value)
    Image.fromarray(scene()).save(tmp_path / "a.jpg")
    with pytest.raises(RtcliError, match="a.jpg: not a PNG"):
        read_png(tmp_path / "a.jpg")
