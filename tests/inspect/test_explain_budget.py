"""explain's node budget (--max-nodes, max_nodes=): the tree shows the depths whose rays fit in
the budget, each ray of the next depth summarised (its ray count and contribution), and its sums
are still the render's.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from click.testing import CliRunner
from helpers import deep

import rtcli
from rtcli.cli import main
from rtcli.inspect.budget import Levels, deepest_shown
from rtcli.rendering.tiles import Job, render
from rtcli.scenefile.load import load_scene


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
