"""Adaptive depth control (render: adc_bailout): a secondary ray whose path weight (the product
of the weights along its path, per channel) is below adc_bailout in every channel is not traced;
the default changes no pixel of the scenes in scenes/; explain shows the same cutoff.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import deep

import rtcli
from rtcli.cli import main
from rtcli.core.scene import Settings
from rtcli.kernels import variants
from rtcli.rendering.tiles import Job, render
from rtcli.scenefile.load import load_scene
from rtcli.wavefront.trace import Log, followed

ROOT = Path(__file__).resolve().parent.parent.parent
ENGINE = "compiled" if variants.ENABLED else "numpy"          # the engines' bytes are the same (test_compiled.py)


class Cuts(Log):
    def __init__(self):
        self.cut = []

    def bailout(self, rows, kind, weights, path):
        self.cut.append((rows.tolist(), kind, path.copy()))


def test_a_ray_is_cut_when_its_path_weight_is_below_the_bailout_in_every_channel():
    scene = SimpleNamespace(settings=SimpleNamespace(adc_bailout=0.01))
    w = np.array([[0.5, 0.5, 0.5, 0.0, 0.02],
                  [0.5, 0.5, 0.001, 0.0, 0.02],
                  [0.5, 0.5, 0.001, 0.0, 0.02]])
    path = np.array([[1.0, 0.01, 0.001, 1.0, 0.5],
                     [1.0, 0.01, 1.0, 1.0, 0.5],
                     [1.0, 0.01, 0.001, 1.0, 0.5]])
    log = Cuts()
    kept = followed(scene, w, path, "reflected", log, np.array([10, 11, 12, 13, 14]))
    # 0: 0.5; 1: 0.005 everywhere (cut); 2: 0.001 in green only (cut); 3: no ray; 4: exactly 0.01 (kept)
    assert kept.tolist() == [0, 4]
    assert [(rows, kind) for rows, kind, _ in log.cut] == [([11, 12], "reflected")]
    np.testing.assert_array_equal(log.cut[0][2], path[:, 1:3] * w[:, 1:3])
    scene.settings.adc_bailout = 0.0
    assert followed(scene, w, path, "refracted", None).tolist() == [0, 1, 2, 4]


def test_the_scene_key_its_default_and_its_errors(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text(deep(bailout="0.0039"))
    assert load_scene(str(path)).settings.adc_bailout == 0.0039
    path.write_text(deep().replace(", adc_bailout: 1.0e-6", ""))
    assert load_scene(str(path)).settings.adc_bailout == Settings().adc_bailout == 1e-6
    docs = (ROOT / "docs" / "scene-format.md").read_text()
    assert "adc_bailout: 1.0e-6" in docs
    out = tmp_path / "out.png"
    for value, message in [("-0.1", "render.adc_bailout: must be >= 0, got -0.1"),
                           ("yes", "render.adc_bailout: must be a number"), (".nan", "adc_bailout")]:
        path.write_text(deep(bailout=value))
        result = CliRunner().invoke(main, ["render", str(path), "-o", str(out)])
        assert result.exit_code == 2 and message in result.output, result.output
        assert result.output.startswith("error: ") and "deep.yaml:5:" in result.output
        assert "Traceback" not in result.output and not out.exists()


@pytest.mark.parametrize("name", ["aquarium", "bubble", "whitted", "csg"])
def test_the_default_changes_no_pixel_of_the_glass_scenes(name):
    """The scenes where the cutoff cuts rays: at their own size (their golden images'), the same
    bytes as with no cutoff; at another size at most one level in a pixel here and there (a cut
    moves a color by less than 1e-6 of a ray's, which shows only at a rounding boundary)."""
    scene = load_scene(str(ROOT / "scenes" / f"{name}.yaml"))
    for w, h in [(scene.settings.width, scene.settings.height), (scene.settings.width // 2, scene.settings.height // 2)]:
        scene.settings.adc_bailout = Settings().adc_bailout
        default, stats = render(scene, Job(w, h, engine=ENGINE))
        scene.settings.adc_bailout = 0.0
        every, stats_every = render(scene, Job(w, h, engine=ENGINE))
        differ = np.abs(default.astype(int) - every).max(axis=2)
        assert differ.max() <= 1 and np.count_nonzero(differ) <= (0 if w == scene.settings.width else 2)
        assert stats.reflected + stats.refracted <= stats_every.reflected + stats_every.refracted
    scene.settings.adc_bailout = 1 / 255                    # POV-Ray's default would change some
    if name in ("aquarium", "bubble"):
        assert not np.array_equal(render(scene, Job(w, h, engine=ENGINE))[0], every)


def test_a_deep_glass_scene_renders_in_bounded_rays(yaml_scene):
    """max_depth 64 with the default cutoff: fewer rays than without it at max_depth 10 (without
    it at max_depth 64, up to 2^63 a pixel), a few dozen a pixel."""
    scene = yaml_scene(deep(64))
    image, stats = render(scene, Job(24, 18, engine="numpy"))
    scene.settings.max_depth = 10
    _, shallow = render(scene, Job(24, 18, engine="numpy"))
    scene.settings.adc_bailout = 0.0
    _, uncut = render(scene, Job(24, 18, engine="numpy"))
    assert stats.reflected + stats.refracted < uncut.reflected + uncut.refracted
    assert stats.reflected < 60 * stats.primary and shallow.reflected < stats.reflected


def test_explain_shows_the_cutoff_and_its_pixel_is_the_render_s(yaml_scene, tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text(deep(bailout="0.0039"))
    image, _ = render(load_scene(str(path)), Job(40, 30))
    e = rtcli.explain(str(path), 25, 17)
    cuts = [cut for node in e.trees[0].walk() for cut in node.bailouts]
    assert cuts and all(cut.path.max() < 0.0039 <= 1 for cut in cuts)
    assert "ray not traced: its path weight (" in e.text() and "is below adc_bailout 0.0039" in e.text()
    assert e.byte.tolist() == image[17, 25].tolist()
    data = json.loads(e.json())
    assert data["samples"][0]["ray"]["children"]
