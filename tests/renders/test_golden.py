"""Golden images: every scene in scenes/ against golden_images/, through rtcli's own compare.

For each scene NAME.yaml there are two goldens: NAME.png (the render) and
NAME.ids.png (the signature's raw ids, 16-bit). `make golden` (pytest
--update-goldens) re-renders only the missing or failing ones and refuses to run
when the CI variable is set; in CI a missing golden fails. A failure leaves
actual, expected and diff images in a folder outside the tree, named in the message.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest

from rtcli.compare import images as compare
from rtcli.core.display import signature_colors
from rtcli.rendering.tiles import Job, render
from rtcli.rendering.writer import write_png
from rtcli.scenefile.load import load_scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted(p for p in (ROOT / "scenes").glob("*.yaml"))
GOLDEN = ROOT / "golden_images"
FAILURES = Path(tempfile.gettempdir()) / "rtcli-golden-failures"


def _param(path: Path):
    return pytest.param(path, id=path.stem)


def _update(request) -> bool:
    if not request.config.getoption("--update-goldens"):
        return False
    if os.environ.get("CI"):
        pytest.fail("refusing to update golden images when CI is set")
    return True


def _check(request, name: str, actual, golden: Path, result_of, diff_of):
    """Compare, update (when asked) or fail with the summary and the images left for inspection."""
    update = _update(request)
    if not golden.exists():
        if update:
            write_png(str(golden), actual)
            return
        pytest.fail(f"{name}: golden image {golden.relative_to(ROOT)} is missing (run `make golden`)")
    expected = compare.read_png(str(golden))
    result = result_of(actual, expected)
    if result.ok:
        return
    if update:
        write_png(str(golden), actual)
        return
    folder = FAILURES / name
    folder.mkdir(parents=True, exist_ok=True)
    write_png(str(folder / "actual.png"), actual)
    write_png(str(folder / "expected.png"), expected)
    if diff_of is not None and actual.shape == expected.shape:
        write_png(str(folder / "diff.png"), diff_of(actual, expected))
    pytest.fail(f"{name}: {result.summary}; images in {folder}")


@pytest.mark.parametrize("path", [_param(p) for p in SCENES])
def test_render_matches_golden(request, path: Path):
    """The render of each scene matches its golden image within the compare gate."""
    scene = load_scene(str(path))
    image, _ = render(scene, Job(scene.settings.width, scene.settings.height), os.cpu_count() or 1)
    _check(request, path.stem, image, GOLDEN / f"{path.stem}.png", compare.compare_images, compare.heat_map)


@pytest.mark.parametrize("path", [_param(p) for p in SCENES])
def test_signature_matches_golden(request, path: Path):
    """The signature (first object hit per pixel) of each scene matches its golden id map."""
    scene = load_scene(str(path))
    ids, _ = render(scene, Job(scene.settings.width, scene.settings.height, signature=True),
                    os.cpu_count() or 1)
    _check(request, f"{path.stem}.ids", ids, GOLDEN / f"{path.stem}.ids.png", compare.compare_ids,
           lambda a, e: compare.heat_map(signature_colors(a), signature_colors(e)))


def test_every_golden_has_a_scene():
    """No stale goldens: each file in golden_images/ belongs to a scene."""
    names = {p.stem for p in SCENES}
    stale = [g.name for g in GOLDEN.glob("*.png") if g.name.split(".")[0] not in names]
    assert not stale, f"golden images without a scene: {stale}"
