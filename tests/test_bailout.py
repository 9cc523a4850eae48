"""Bounded ray trees: adaptive depth control (render: adc_bailout) and explain's node budget.

A secondary ray whose path weight (the product of the weights along its path, per channel) is
below adc_bailout in every channel is not traced; the default changes no pixel of the scenes in
scenes/; explain shows the same cutoff and summarises the rays past its node budget.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

import rtcli
from rtcli.cli import main
from rtcli.core.scene import Settings
from rtcli.inspect.budget import Levels, deepest_shown
from rtcli.kernels import variants
from rtcli.rendering.tiles import Job, render
from rtcli.scenefile.load import load_scene
from rtcli.wavefront.trace import Log, followed

ROOT = Path(__file__).resolve().parent.parent
ENGINE = "compiled" if variants.ENABLED else "numpy"          # the engines' bytes are the same (test_compiled.py)

# Two glass balls inside a third: most rays stay inside, and each surface sends two on.
DEEP = """
image: {width: 40, height: 30}
camera: {eye: [0, 0, 4.5], look_at: [0, 0, 0], fov: 50}
background: [0.3, 0.5, 0.8]
render: {max_depth: DEPTH, adc_bailout: BAILOUT}
lights: [{position: [2, 2.5, 3]}]
materials:
  glass: {diffuse: 0.1, reflection: REFLECTION, transmission: TRANSMISSION, ior: 1.5, fresnel: FRESNEL}
objects:
  - {sphere: {center: [-1, 0, 0], radius: 0.9}, material: glass}
  - {sphere: {center: [1, 0, 0], radius: 0.9}, material: glass}
  - {sphere: {center: [0, 0, 0], radius: 6}, material: glass}
"""


def deep(depth=20, bailout="1.0e-6", reflection="1", transmission="1", fresnel="true") -> str:
    return (DEEP.replace("DEPTH", str(depth)).replace("BAILOUT", bailout).replace("REFLECTION", reflection)
            .replace("TRANSMISSION", transmission).replace("FRESNEL", fresnel))


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


def count(node) -> int:
    return node.more or 1 + sum(count(child) for child in node.children)


def test_past_the_node_budget_rays_are_summarised_and_still_add_up(tmp_path):
    """No cutoff and weights that halve: every ray of the tree is traced; the tree shows the
    depths that fit in the budget, the next one summarised, and the sums are the render's."""
    path = tmp_path / "deep.yaml"
    path.write_text(deep(9, "0", "0.5", "0.5", "false"))
    whole = rtcli.explain(str(path), 25, 17, max_nodes=1_000_000).trees[0]
    rays = sum(1 for _ in whole.walk())
    for budget in (1, 10, 100):
        e = rtcli.explain(str(path), 25, 17, max_nodes=budget)
        tree = e.trees[0]
        shown = [node for node in tree.walk() if not node.more]
        summaries = [node for node in tree.walk() if node.more]
        assert len(shown) <= budget < rays and summaries and count(tree) == rays
        assert len({node.depth for node in summaries}) == 1 and max(n.depth for n in shown) < summaries[0].depth
        np.testing.assert_array_equal(tree.total(), whole.total())
        np.testing.assert_array_equal(e.value, whole.value)
        assert all(not node.children and node.hit is None for node in summaries)
    text = rtcli.explain(str(path), 25, 17, max_nodes=10).text()
    assert "more rays (this one and those below it, past the node budget: --max-nodes), total contribution (" in text


def test_deepest_shown():
    count = {1: 1, 2: 2, 3: 4, 4: 8}
    assert deepest_shown(count, 15) is None and deepest_shown(count, 14) == 3
    assert deepest_shown(count, 7) == 3 and deepest_shown(count, 6) == 2 and deepest_shown(count, 1) == 1
    levels = Levels()
    levels.rays([0, 0], 2, None)
    levels.rays([0] * 5, 2, None)
    assert levels.count == {2: 7}


def test_explain_command_max_nodes_bounds_text_and_json(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text(deep(12, "0", "0.5", "0.5", "false"))
    run = lambda *args: CliRunner().invoke(main, ["explain", str(path), "25", "17", *args])   # noqa: E731
    start = time.monotonic()
    text, data = run("--max-nodes", "50"), run("--max-nodes", "50", "--json")
    assert text.exit_code == data.exit_code == 0, text.output + data.output
    assert "more rays (this one" in text.output and text.output.count("ray, depth") < 150
    tree = json.loads(data.output)["samples"][0]["ray"]
    nodes, stack = [], [tree]
    while stack:
        nodes.append(stack.pop())
        stack += nodes[-1]["children"]
    assert [n for n in nodes if n["more"] and "contribution" in n] and len(nodes) < 150
    assert time.monotonic() - start < 120                       # a bound on a runaway, not a speed test
    for value in ("0", "-3", "many"):
        result = run("--max-nodes", value)
        assert result.exit_code == 2 and "--max-nodes" in result.output and "Traceback" not in result.output
    with pytest.raises(rtcli.RtcliError, match="max_nodes must be an integer in 1..1000000, got 0"):
        rtcli.explain(str(path), 25, 17, max_nodes=0)


def test_a_deep_glass_scene_explains_in_bounded_output(tmp_path):
    """The scene that used to print hundreds of megabytes: Fresnel glass at max_depth 20, explained
    with the scene's default cutoff and the default node budget, as text and as JSON."""
    path = tmp_path / "deep.yaml"
    path.write_text(deep(20).replace(", adc_bailout: 1.0e-6", ""))
    run = lambda *args: CliRunner().invoke(main, ["explain", str(path), "25", "17", *args])   # noqa: E731
    text, data = run(), run("--json")
    assert text.exit_code == data.exit_code == 0, text.output + data.output
    assert text.output.count("ray, depth") <= 3000 and len(text.output) < 3_000_000
    assert len(data.output) < 30_000_000
    image, _ = render(load_scene(str(path)), Job(40, 30))
    assert json.loads(data.output)["byte"] == image[17, 25].tolist()
    assert f"-> 8-bit {tuple(image[17, 25].tolist())}" in text.output
