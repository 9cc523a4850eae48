"""The documents' examples run: the tutorial and the API's Python blocks, and the CI scripts.

A ```python block runs in one namespace with the blocks before it, in a scratch
folder; when an ```output block follows it, what it printed must equal that block.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import junitparser
import pytest
import xmlschema

ROOT = Path(__file__).resolve().parents[2]
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.M | re.S)


def blocks(doc: str) -> list[tuple[str, str]]:
    return BLOCK.findall((ROOT / "docs" / doc).read_text())


def run_python_blocks(doc: str) -> int:
    """Run the document's Python blocks, checking their printed output; how many ran."""
    found, namespace, ran = blocks(doc), {"__name__": "__doc_example__"}, 0
    for k, (kind, code) in enumerate(found):
        if kind != "python":
            continue
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, f"{doc} block {k}", "exec"), namespace)
        ran += 1
        if k + 1 < len(found) and found[k + 1][0] == "output":
            assert printed.getvalue() == found[k + 1][1], f"{doc} block {k}"
    return ran


@pytest.mark.parametrize("doc", ["tutorial.md", "python-api.md"])
def test_python_blocks_run_and_print_what_the_document_says(doc, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    assert run_python_blocks(doc) >= 3


SCENE = """\
image: {width: 24, height: 18}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
lights: [{position: [5, 5, 5]}]
objects: [{name: ball, sphere: {radius: 1}, material: {diffuse: [%s]}}]
"""


def test_the_ci_example_passes_then_catches_a_change(tmp_path):
    """docs/ci.md: make the goldens, run ci/golden.sh (exit 0), change a scene, run it again (exit 1),
    break a scene: exit 2, and the other scene is still rendered, compared and reported."""
    make_goldens, script = [code for kind, code in blocks("ci.md") if kind == "sh"]
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "red.yaml").write_text(SCENE % "1, 0, 0")
    (tmp_path / "scenes" / "blue.yaml").write_text(SCENE % "0, 0, 1")
    (tmp_path / "ci").mkdir()
    (tmp_path / "ci" / "golden.sh").write_text(script)
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}

    def sh(text: str):
        return subprocess.run(["sh", "-c", text], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert sh(make_goldens).returncode == 0
    passed = sh("sh ci/golden.sh")
    assert passed.returncode == 0, passed.stdout + passed.stderr
    assert passed.stdout.splitlines()[-1] == "OK: 2 pairs: 2 ok, 0 failing, 0 missing, 0 extra, 0 unreadable"
    (tmp_path / "scenes" / "blue.yaml").write_text(SCENE % "0, 0.5, 1")
    failed = sh("sh ci/golden.sh")
    assert failed.returncode == 1
    assert "blue.png: FAIL" in failed.stdout
    assert '<tr class="pair failing failure"' in (tmp_path / "report" / "index.html").read_text()
    suite = next(iter(junitparser.JUnitXml.fromfile(str(tmp_path / "junit.xml"))))
    assert (suite.tests, suite.failures) == (2, 1)
    assert len((tmp_path / "renders.jsonl").read_text().splitlines()) == 2
    (tmp_path / "scenes" / "blue.yaml").write_text(SCENE.replace("radius: 1", "raduis: 1") % "0, 0, 1")
    broken = sh("sh ci/golden.sh")
    assert broken.returncode == 2
    assert broken.stderr == ("error: scenes/blue.yaml:4:33: objects[0].sphere.raduis: unknown key (did you mean "
                             "'radius'?); allowed here: center, radius\n")
    assert broken.stdout.splitlines() == [
        "blue.png: MISSING: no actual image for golden/blue.png", "red.png: " + passed.stdout.splitlines()[1][9:],
        "FAIL: 2 pairs: 1 ok, 0 failing, 1 missing, 0 extra, 0 unreadable"]
    assert [json.loads(line)["scene"] for line in (tmp_path / "renders.jsonl").read_text().splitlines()] == [
        "scenes/red.yaml"]
    html = (tmp_path / "report" / "index.html").read_text()
    assert '<tr class="pair missing error"' in html and '<tr class="pair ok"' in html
    xmlschema.XMLSchema(str(ROOT / "tests" / "data" / "JUnit.xsd")).validate(str(tmp_path / "junit.xml"))
    suite = next(iter(junitparser.JUnitXml.fromfile(str(tmp_path / "junit.xml"))))
    assert (suite.tests, suite.failures, suite.errors) == (2, 0, 1)
    assert {case.name: [type(r).__name__ for r in case.result] for case in suite} == {"blue.png": ["Error"],
                                                                                      "red.png": []}


def test_the_debugging_guide_shows_what_explain_prints(monkeypatch):
    """docs/debugging.md: each ```console block's command, run from the repository, prints the block."""
    from click.testing import CliRunner

    from rtcli.cli import main
    monkeypatch.chdir(ROOT)
    consoles = [code for kind, code in blocks("debugging.md") if kind == "console"]
    assert len(consoles) >= 3
    for code in consoles:
        command, expected = code.split("\n", 1)
        assert command.startswith("$ rtcli ")
        result = CliRunner().invoke(main, command.split()[2:])
        assert result.exit_code == 0 and result.output == expected, command
