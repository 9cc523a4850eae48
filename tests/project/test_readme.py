"""README.md's commands run as written, in a copy of the repository, and leave `git status` clean.

Every `rtcli ...` line of the README's code blocks (indented or fenced, with or without
a `$ ` prompt) is listed below, either with what it must do (its exit code and the
files it writes) or, for the few that cannot run here, with the reason and the test
that covers them elsewhere. A line added to the README without an entry here, or an
entry whose line left the README, fails the test. The lines run in README order through
`sh -c`, exactly as written; only sizes are reduced, by appending `--width`/`--height`
(the last of click's repeated options wins), for the lines of SMALLER. The Python
example runs too, and a `$ rtcli` line followed by its output must print that output.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

pytestmark = pytest.mark.slow   # every command of the README, at small sizes, in a copy of the clone

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
COPIED = ["scenes", "golden_images", "README.md", ".gitignore", "Makefile", "pyproject.toml"]
SCENES = sorted(p.stem for p in (ROOT / "scenes").glob("*.yaml"))
FLIP = importlib.util.find_spec("flip_evaluator") is not None      # the extra `flip` (the Makefile installs it)

# The README's line -> the size options appended when it runs here (nothing else changes).
SMALLER = {
    "rtcli render scenes/whitted.yaml -o big.png --width 1920 --height 1080 --stats": "--width 96 --height 54",
    "rtcli render scenes/presets.yaml --samples 3 --gamma": "--width 64",
    "rtcli render scenes/orbit.yaml --frames 1-24 -o out/frame_%04d.png": "--width 32",
    "rtcli render scenes/orbit.yaml -o orbit.gif": "--width 32",
    "rtcli render dark.yaml": "--width 64",
    "rtcli render scenes/whitted.yaml -o whitted.exr --layers normal,depth,albedo,ids": "--width 64",
    "rtcli render scenes/whitted.yaml -o whitted.pfm": "--width 64",
    "rtcli render scenes/whitted.yaml -o whitted16.png --bit-depth 16 --gamma": "--width 64",
    "rtcli render scenes/whitted.yaml -o cutout.png --alpha": "--width 64",
}

# The README's line -> why it does not run here, and where it is tested.
ELSEWHERE = {
    "rtcli render scenes/whitted.yaml --cluster tcp://127.0.0.1:8786":
        "needs a Dask scheduler at that address: tests/cluster/test_cluster.py renders on clusters it starts",
    "rtcli render scenes/whitted.yaml --watch": "runs until Ctrl-C: tests/rendering/test_watch.py",
    "rtcli render scene.yaml --watch": "runs until Ctrl-C, on a scene of the reader's: tests/rendering/test_watch.py",
    "rtcli warmup": "compiles the compiled engine (minutes with a cold cache): tests/compiled/test_startup.py",
    "rtcli preview scenes/whitted.yaml": "serves a page until Ctrl-C: tests/preview/test_preview.py, and in a browser "
                                         "tests/preview/test_preview_browser.py",
    "rtcli warmup --cluster tcp://127.0.0.1:8786":
        "needs a Dask scheduler at that address: tests/cluster/test_cluster.py warms clusters it starts",
}

# The README's line -> (exit code, files it writes), in the copy's folder.
EXPECTED = {
    "rtcli render scenes/whitted.yaml": (0, ["whitted.png"]),
    "rtcli render scenes/whitted.yaml -o big.png --width 1920 --height 1080 --stats": (0, ["big.png"]),
    "rtcli render scenes/whitted.yaml --block-size 8 -o preview.png": (0, ["preview.png"]),
    "rtcli render scenes/presets.yaml --samples 3 --gamma": (0, ["presets.png"]),
    "rtcli render scenes/orbit.yaml --frames 1-24 -o out/frame_%04d.png":
        (0, [f"out/frame_{k:04d}.png" for k in range(1, 25)]),
    "rtcli render scenes/orbit.yaml -o orbit.gif": (0, ["orbit.gif"]),
    "rtcli signature scenes/csg.yaml -o sig.png --ids ids.png --legend": (0, ["sig.png", "ids.png"]),
    "rtcli explain scenes/whitted.yaml 320 240": (0, []),
    "rtcli render scenes/inspect.yaml --view normal": (0, ["inspect.normal.png"]),
    "rtcli compare whitted.png golden_images/whitted.png --diff diff.png": (0, ["diff.png"]),
    "rtcli compare ids.png golden_images/csg.ids.png --ids": (0, []),
    "rtcli compare whitted.png golden_images/whitted.png --flip flip.png": (0, ["flip.png"]) if FLIP else (2, []),
    "rtcli render scenes -o renders --stats --json": (0, [f"renders/{name}.png" for name in SCENES]),
    "rtcli render scenes -o renders --view ids --keep-going": (0, [f"renders/{name}.ids.png" for name in SCENES]),
    "rtcli compare renders golden_images --report report --junit junit.xml": (0, ["report/index.html", "junit.xml"]),
    "rtcli validate scenes/bunny.yaml": (0, []),
    "rtcli validate scenes/whitted.yaml --objects --strict": (0, []),
    "rtcli presets": (0, []),
    "rtcli validate scenes/whitted.yaml --objects": (0, []),
    "rtcli validate dark.yaml": (0, []),
    "rtcli render dark.yaml": (0, ["dark.png"]),
    "rtcli render scenes/whitted.yaml -o whitted.exr --layers normal,depth,albedo,ids": (0, ["whitted.exr"]),
    "rtcli render scenes/whitted.yaml -o whitted.pfm": (0, ["whitted.pfm"]),
    "rtcli render scenes/whitted.yaml -o whitted16.png --bit-depth 16 --gamma": (0, ["whitted16.png"]),
    "rtcli render scenes/whitted.yaml -o cutout.png --alpha": (0, ["cutout.png"]),
    "rtcli info whitted.exr": (0, []),
    "rtcli compare whitted.pfm whitted.exr --float-tolerance 0.001": (0, []),
}


def code_lines(text: str) -> list[str]:
    """The lines of the README's code blocks: fenced, or indented by four spaces."""
    found, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        elif fenced or line.startswith("    "):
            found.append(line.strip())
    return found


def readme_commands(text: str = README) -> list[str]:
    """Each `rtcli ...` line of the code blocks, its prompt and comment dropped, continuations joined."""
    commands, lines = [], code_lines(text)
    for k, line in enumerate(lines):
        line = line.removeprefix("$ ")
        if not line.startswith("rtcli "):
            continue
        while line.endswith("\\"):
            k += 1
            line = line[:-1] + lines[k]
        commands.append(" ".join(shlex.split(line, comments=True)))
    return commands


def shown_output(command: str, text: str = README) -> list[str] | None:
    """The lines the README shows under `$ COMMAND` (up to a blank line), or None."""
    match = re.search(rf"^    \$ {re.escape(command)}\n((?:    .*\S.*\n)*)", text, re.M)
    return None if match is None else [line[4:] for line in match.group(1).splitlines()]


def scene_before(command: str, text: str = README) -> str:
    """The ```yaml block that comes last before the line `$ COMMAND`."""
    head = text[:text.index(f"$ {command}")]
    return re.findall(r"^```yaml\n(.*?)^```$", head, re.M | re.S)[-1]


def python_example(text: str = README) -> str:
    """The indented block of README.md's Python section, from `import rtcli`."""
    section = text[text.index("\n## Python\n"):]
    block = re.search(r"^    import rtcli\n(?:    .*\n)*", section, re.M).group(0)
    return "\n".join(line[4:] for line in block.splitlines()) + "\n"


def test_every_readme_command_is_run_here_or_listed_with_its_reason():
    commands = set(readme_commands())
    assert commands - set(EXPECTED) - set(ELSEWHERE) == set(), "README lines without an entry here"
    assert (set(EXPECTED) | set(ELSEWHERE)) - commands == set(), "entries whose line left the README"
    assert set(SMALLER) <= set(EXPECTED)
    assert all(re.fullmatch(r"(--(width|height) \d+ ?)+", extra) for extra in SMALLER.values())


def test_the_extraction_finds_prompts_comments_and_continuations():
    text = ("Text `rtcli not this`.\n\n    rtcli render a.yaml -o 'x y.png'   # a comment\n    $ rtcli presets\n"
            "    output\n\n```sh\nrtcli compare a b \\\n    --ids\n```\n    rtcli explain s.yaml 1 2\n")
    assert readme_commands(text) == ["rtcli render a.yaml -o x y.png", "rtcli presets", "rtcli compare a b --ids",
                                     "rtcli explain s.yaml 1 2"]
    assert shown_output("rtcli presets", text) == ["output"]


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """A copy of the repository under git, where every README command has run, in order, and then
    the Python example (what it printed under the key "python")."""
    where = tmp_path_factory.mktemp("readme") / "rtcli"
    where.mkdir()
    for name in COPIED:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, where / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(source, where / name)
    git(where, "init", "-q")
    git(where, "add", "-A")
    git(where, "-c", "user.name=rtcli", "-c", "user.email=rtcli@localhost", "commit", "-q", "-m", "copy")
    (where / "dark.yaml").write_text(scene_before("rtcli validate dark.yaml"))     # the reader writes it
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    results = {}
    for command in readme_commands():
        if command in ELSEWHERE or command in results:
            continue
        line = f"{command} {SMALLER.get(command, '')}".strip()
        results[command] = subprocess.run(["sh", "-c", line], cwd=where, env=env, capture_output=True, text=True,
                                          timeout=600)
    (where / "dark.yaml").unlink()
    results["python"] = run_python(python_example(), where)
    return where, results


def run_python(code: str, where: Path) -> str:
    """Run the code in this process (the rtcli under test), in the folder `where`; what it printed."""
    printed, before = io.StringIO(), os.getcwd()
    os.chdir(where)
    try:
        with contextlib.redirect_stdout(printed):
            exec(compile(code, "README.md, Python", "exec"), {"__name__": "__readme__"})
    finally:
        os.chdir(before)
    return printed.getvalue()


def git(where: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=where, capture_output=True, text=True, check=True).stdout


@pytest.mark.parametrize("command", list(EXPECTED))
def test_each_command_exits_as_expected_and_writes_its_files(session, command):
    where, results = session
    done = results[command]
    code, files = EXPECTED[command]
    assert done.returncode == code, f"{command}\n{done.stdout[-2000:]}{done.stderr[-2000:]}"
    assert "Traceback" not in done.stderr
    for name in files:
        assert (where / name).is_file() and (where / name).stat().st_size > 0, f"{command}: {name}"


def test_sizes_are_reduced_only_where_listed(session):
    where, _ = session
    assert Image.open(where / "whitted.png").size == (640, 480)
    assert Image.open(where / "big.png").size == (96, 54)
    assert Image.open(where / "out" / "frame_0024.png").size[0] == 32
    assert getattr(Image.open(where / "orbit.gif"), "n_frames", 1) == 24


def test_comparisons_against_the_goldens_pass_pair_by_pair(session):
    """`render scenes` and `render scenes --view ids` write the files of golden_images/, and every
    pair passes; the JSON lines are one a scene on a pure stdout."""
    where, results = session
    lines = [json.loads(line) for line in results["rtcli render scenes -o renders --stats --json"].stdout.splitlines()]
    assert [Path(d["output"]).name for d in lines] == [f"{name}.png" for name in SCENES]
    assert sorted(p.name for p in (where / "renders").iterdir()) == sorted(p.name for p in
                                                                            (where / "golden_images").iterdir())
    compared = results["rtcli compare renders golden_images --report report --junit junit.xml"].stdout
    assert compared.splitlines()[-1] == (f"OK: {2 * len(SCENES)} pairs: {2 * len(SCENES)} ok, 0 failing, "
                                         "0 missing, 0 extra, 0 unreadable")
    ids = np.asarray(Image.open(where / "ids.png"))
    assert ids.dtype == np.uint16 and np.array_equal(ids, np.asarray(Image.open(where / "renders" / "csg.ids.png")))
    for command in ("rtcli compare whitted.png golden_images/whitted.png --diff diff.png",
                    "rtcli compare ids.png golden_images/csg.ids.png --ids"):
        assert results[command].stdout.startswith("OK: "), command


def test_shown_outputs_are_what_the_commands_print(session):
    """A `$ rtcli ...` line followed by lines shows what it prints (stdout, then stderr)."""
    _, results = session
    shown = {c: shown_output(c) for c in readme_commands() if c not in ELSEWHERE and shown_output(c)}
    assert set(shown) == {"rtcli validate scenes/whitted.yaml --objects", "rtcli validate dark.yaml",
                          "rtcli render dark.yaml"}
    for command, lines in shown.items():
        done = results[command]
        assert (done.stdout + done.stderr).splitlines() == lines, command


def test_the_python_example_runs(session):
    """It saves the 320 x 240 render and prints the comparison of 2 x 2 samples against 1."""
    where, results = session
    assert re.fullmatch(r"(OK|FAIL): \d+ bad pixels? .*\n", results["python"])
    assert Image.open(where / "whitted-small.png").size == (320, 240)


def test_the_commands_leave_git_status_clean(session):
    """Everything the README's commands (and its Python example) write is ignored by git."""
    where, _ = session
    written = [p for p in where.iterdir() if p.name not in COPIED + [".git"]]
    assert len(written) >= 10                                    # the check can fail
    assert git(where, "status", "--porcelain", "--untracked-files=all") == ""
