"""`rtcli compare` on two folders: pairing, exit codes, the HTML report and the JUnit file.

The JUnit file is validated against the Apache Ant JUnit schema (tests/data/JUnit.xsd,
Windy Road's, under the Apache License 2.0 its header states) and read back with
junitparser, as CI systems read it. The report is opened in headless Chromium when
/usr/bin/chromium is installed (.ci/run installs it).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import junitparser
import numpy as np
import pytest
import xmlschema
from click.testing import CliRunner
from PIL import Image

from rtcli.cli import main

SCHEMA = Path(__file__).parents[1] / "data" / "JUnit.xsd"
CHROMIUM = "/usr/bin/chromium"


def picture(seed: int, shape=(24, 32, 3)) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, shape, dtype=np.uint8)


@pytest.fixture
def folders(tmp_path, monkeypatch):
    """actual/ and expected/ with one pair of each status, an id map and a subfolder."""
    monkeypatch.chdir(tmp_path)
    for side in ("actual", "expected", "actual/sub", "expected/sub"):
        (tmp_path / side).mkdir()
    for side in ("actual", "expected"):
        Image.fromarray(picture(1)).save(tmp_path / side / "same.png")
        Image.fromarray(picture(2)).save(tmp_path / side / "sub" / "deep.png")
        Image.fromarray(np.arange(24 * 32, dtype=np.uint16).reshape(24, 32) % 7).save(tmp_path / side / "s.ids.png")
    changed = picture(3)
    Image.fromarray(changed).save(tmp_path / "expected" / "changed.png")
    changed[4:12, 4:12] ^= 0x80
    Image.fromarray(changed).save(tmp_path / "actual" / "changed.png")
    Image.fromarray(picture(4)).save(tmp_path / "expected" / "gone.png")
    Image.fromarray(picture(5)).save(tmp_path / "actual" / "new.png")
    (tmp_path / "actual" / "broken.png").write_bytes(b"not a png")
    Image.fromarray(picture(6)).save(tmp_path / "expected" / "broken.png")
    return tmp_path


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_pairs_by_relative_path_and_fails_on_any_problem(folders):
    result = run("compare", "actual", "expected")
    assert result.exit_code == 1
    lines = result.output.splitlines()
    assert [line.split(": ")[0:2] for line in lines[:-1]] == [
        ["broken.png", "UNREADABLE"], ["changed.png", "FAIL"], ["gone.png", "MISSING"], ["new.png", "EXTRA"],
        ["s.ids.png", "OK"], ["same.png", "OK"], ["sub/deep.png", "OK"]]
    assert lines[-1] == "FAIL: 7 pairs: 3 ok, 1 failing, 1 missing, 1 extra, 1 unreadable"


def test_all_pairs_passing_exits_0(folders):
    for name in ("changed.png", "new.png", "broken.png"):
        (folders / "actual" / name).unlink()
    for name in ("changed.png", "gone.png", "broken.png"):
        (folders / "expected" / name).unlink()
    result = run("compare", "actual", "expected")
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[-1] == "OK: 3 pairs: 3 ok, 0 failing, 0 missing, 0 extra, 0 unreadable"


@pytest.mark.parametrize("args, message", [
    (["actual", "expected/same.png"], "actual is a folder but expected/same.png is not: compare two folders or "
                                      "two images"),
    (["expected/same.png", "actual"], "actual is a folder but expected/same.png is not"),
    (["actual", "golden"], "golden: no such folder (to compare with the folder actual)"),
    (["golden", "expected", "--report", "r", "--junit", "j.xml"], "golden: no such folder (to compare with the "
                                                                  "folder expected)"),
    (["renders", "golden", "--report", "r"], "renders: no such file or folder"),
    (["actual/same.png", "gone.png"], "gone.png: no such file"),
    (["actual", "expected", "--diff", "d.png"], "--diff, --flip and --ids compare two images"),
    (["actual/same.png", "expected/same.png", "--junit", "j.xml"], "--report and --junit compare two folders"),
    (["actual", "expected", "--report", "actual/r"], "actual/r: the report folder must be outside the compared"),
    (["actual", "expected", "--report", "kept"], "kept: a folder that is neither empty nor an rtcli report"),
    (["actual", "expected", "--junit", "actual/same.png"], "actual/same.png: is an input of this run"),
    (["empty", "empty"], "no .png, .exr or .pfm images under empty or empty"),
])
def test_bad_usage_exits_2_and_writes_nothing(folders, args, message):
    (folders / "kept").mkdir()
    (folders / "kept" / "notes.txt").write_text("mine")
    (folders / "empty").mkdir()
    before = sorted(str(p) for p in folders.rglob("*"))
    result = run("compare", *args)
    assert result.exit_code == 2
    assert result.output.startswith(f"error: {message}") and result.output.count("\n") == 1
    assert sorted(str(p) for p in folders.rglob("*")) == before


def test_junit_file_follows_the_schema_and_reads_as_test_results(folders):
    assert run("compare", "actual", "expected", "--junit", "results.xml").exit_code == 1
    xmlschema.XMLSchema(str(SCHEMA)).validate("results.xml")
    suite = next(iter(junitparser.JUnitXml.fromfile("results.xml")))
    assert (suite.tests, suite.failures, suite.errors) == (7, 2, 2)
    outcome = {case.name: [type(r).__name__ for r in case.result] for case in suite}
    assert outcome == {"broken.png": ["Error"], "changed.png": ["Failure"], "gone.png": ["Error"],
                       "new.png": ["Failure"], "s.ids.png": [], "same.png": [], "sub/deep.png": []}
    failure = next(case for case in suite if case.name == "changed.png").result[0]
    assert failure.message.startswith("FAIL: 64 bad pixels (limit 16)")
    missing = next(case for case in suite if case.name == "gone.png").result[0]
    assert (missing.type, missing.message) == ("missing", "MISSING: no actual image for expected/gone.png")


def test_report_replaces_an_earlier_report_only(folders):
    assert run("compare", "actual", "expected", "--report", "report").exit_code == 1
    first = (folders / "report" / "index.html").read_text()
    assert first.count('<tr class="pair ') == 7
    (folders / "actual" / "new.png").unlink()
    assert run("compare", "actual", "expected", "--report", "report").exit_code == 1
    assert (folders / "report" / "index.html").read_text().count('<tr class="pair ') == 6
    assert not [p for p in folders.iterdir() if p.name.startswith(".rtcli")]       # no temporary folder left


def test_report_rows_are_worst_first_with_their_pictures(folders):
    run("compare", "actual", "expected", "--report", "report")
    html = (folders / "report" / "index.html").read_text()
    rows = re.findall(r'<tr class="pair ([\w ]+)"', html)
    assert rows == ["unreadable error", "missing error", "extra failure", "failing failure", "ok", "ok", "ok"]
    for name in re.findall(r'<img src="([^"]+)"', html):
        assert (folders / "report" / name).is_file()
    assert html.count('-difference.png"') == 2 * 4                 # link and picture of the 4 comparable pairs


def test_a_golden_without_a_render_is_an_error_row_showing_the_golden(folders):
    run("compare", "actual", "expected", "--report", "report")
    html = (folders / "report" / "index.html").read_text()
    row = re.search(r'<tr class="pair missing error".*?</tr>', html).group(0)
    assert '<span class="result">error</span>' in row and "MISSING: no actual image for expected/gone.png" in row
    pictures = re.findall(r'<img src="([^"]+)" alt="(\w+) of gone.png"', row)
    assert [column for _, column in pictures] == ["expected"]
    shown = np.asarray(Image.open(folders / "report" / pictures[0][0]))
    assert np.array_equal(shown, np.asarray(Image.open(folders / "expected" / "gone.png")))


@pytest.mark.skipif(not os.path.exists(CHROMIUM), reason="needs Debian's chromium (.ci/run installs it)")
def test_report_shows_every_row_and_picture_in_a_browser(folders, tmp_path):
    run("compare", "actual", "expected", "--report", "report")
    html = (folders / "report" / "index.html").read_text()
    pictures = html.count("<img ")
    dom = chromium("--virtual-time-budget=10000", "--dump-dom", (folders / "report" / "index.html").as_uri(),
                   profile=tmp_path / "profile")
    assert len(re.findall(r'<tr class="pair [\w ]+" id="pair-\d+">', dom)) == 7
    assert f'data-images-loaded="{pictures}"' in dom and 'class="broken"' not in dom
    shutil.rmtree(folders / "report" / "images")
    dom = chromium("--virtual-time-budget=10000", "--dump-dom", (folders / "report" / "index.html").as_uri(),
                   profile=tmp_path / "profile2")
    assert 'data-images-loaded="0"' in dom                          # the check can fail


def chromium(*args, profile: Path) -> str:
    done = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                           "--disable-component-update", "--disable-sync", "--no-first-run",
                           f"--user-data-dir={profile}", *args], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout
