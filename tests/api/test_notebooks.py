"""rtcli in notebooks: an explanation shows as its tree, an rtcli error as its one-line message
(IPython's `_repr_pretty_` and `_render_traceback_` conventions), tested by calling the methods
and, when IPython is installed, in a real IPython shell."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

import rtcli
from rtcli.cli import main

WHITTED = str(Path(__file__).resolve().parents[2] / "scenes" / "whitted.yaml")
BAD = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nobjects: [{sphere: {radius: -1}}]\n"
BAD_LINE = "SceneError: <string>:2:29: objects[0].sphere.radius: must be > 0, got -1"


class Printer:
    """The part of IPython's pretty printer that _repr_pretty_ uses."""

    def __init__(self):
        self.parts = []

    def text(self, text: str) -> None:
        self.parts.append(text)


def test_an_explanation_shows_the_tree_rtcli_explain_prints():
    e = rtcli.explain(WHITTED, 32, 24, width=64)
    shown = Printer()
    e._repr_pretty_(shown, False)
    printed = CliRunner().invoke(main, ["explain", WHITTED, "32", "24", "--width", "64"], color=False).stdout
    assert "".join(shown.parts) + "\n" == printed
    assert repr(e) == ("<rtcli Explanation of pixel (32, 24) of 64x48 = (0.465424, 0.109501, 0.144881) -> 8-bit "
                       "(119, 28, 37); print() shows its tree>")
    node = e.trees[0].children[0]
    node._repr_pretty_(shown := Printer(), False)
    assert shown.parts == [str(node)] and str(node).startswith("reflected ray, depth 2: from ")
    assert repr(node) == "<rtcli RayNode: reflected ray, depth 2, hits #2 mirror ball; print() shows its tree>"


def test_an_rtcli_error_renders_as_its_one_line_message():
    with pytest.raises(rtcli.SceneError) as caught:
        rtcli.load_scene(BAD)
    assert caught.value._render_traceback_() == [BAD_LINE]
    with pytest.raises(rtcli.RtcliError) as caught:
        rtcli.render(WHITTED, samples=17)
    assert caught.value._render_traceback_() == ["RtcliError: samples must be an integer in 1..16, got 17"]


def test_in_an_ipython_shell(tmp_path):
    """A tiny IPython session, in its own process: the explanation's tree is the cell's output, the
    error one line with no traceback."""
    pytest.importorskip("IPython")
    cells = [f"rtcli.explain({WHITTED!r}, 32, 24, width=64)", f"rtcli.load_scene({BAD!r})"]
    script = textwrap.dedent(f"""
        from IPython.core.interactiveshell import InteractiveShell
        shell = InteractiveShell.instance()
        shell.run_cell("import rtcli")
        shell.run_cell({cells[0]!r})
        print("--- next cell")
        result = shell.run_cell({cells[1]!r})
        print("--- failed:", type(result.error_in_exec).__name__)
    """)
    env = dict(os.environ, IPYTHONDIR=str(tmp_path / "ipython"))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300)
    explained, error = run.stdout.split("--- next cell\n")
    assert explained.splitlines()[:2] == ["Out[0]: ", "pixel (32, 24) of 64x48 = (0.465424, 0.109501, 0.144881) "
                                                     "-> 8-bit (119, 28, 37)"]
    assert "Explanation(" not in explained and "glass ball (sphere)" in explained
    assert error == f"{BAD_LINE}\n--- failed: SceneError\n"
