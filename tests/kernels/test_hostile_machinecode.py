"""Hostile machine code files (docs/architecture.md, Trust in the machine code files): whatever
is found in the cache folder, a render never opens a library it did not write, never crashes
or hangs, takes numba's path and gives the same pixels, and `--stats` says why in one line."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rtcli import compiled as fast
from rtcli.compiled import build as compiled_build
from rtcli.kernels import machinecode, variants
from rtcli.kernels.machinecode import entries, places, writing
from rtcli.rendering.engine import choose

pytestmark = [pytest.mark.slow,   # machine code files written and planted, processes of their own
              pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")]

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "whitted.yaml"

RENDER = """
import sys
from pathlib import Path
from rtcli.kernels.machinecode import places
places.folder = lambda: Path(sys.argv[1])
from rtcli.cli import main
main(["render", sys.argv[2], "-o", sys.argv[3], "--width", "48", "--height", "36", "--engine", "compiled",
      "--stats", "--quiet"])
"""

PLANTED = """#include <stdio.h>
__attribute__((constructor)) static void planted(void) {{
    FILE *f = fopen("{marker}", "w");
    if (f) {{ fputs("ran", f); fclose(f); }}
}}
int rtcli_entry(void *words, void *floats, void *results) {{ return 0; }}
"""


@pytest.fixture(scope="module")
def files():
    """The engine's machine code files, beside numba's cache (made if missing)."""
    if machinecode.folder() is None:
        pytest.skip("no cache folder")
    from rtcli.rendering.warmup import _scenes, machine_code
    entries._loaded.clear()
    made, why = machine_code(choose(_scenes()[0], "compiled", notes=lambda text: None))
    assert made == [fast.ENTRY, compiled_build.LEVELS], why
    return machinecode.folder()


def render(place: Path, out: Path) -> tuple[np.ndarray, list[str]]:
    """Render the scene in a process of its own whose machine code files are in `place`: (its
    pixels, the notes it printed)."""
    done = subprocess.run([sys.executable, "-c", RENDER, str(place), str(SCENE), str(out)], capture_output=True,
                          text=True, cwd=ROOT, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    return np.asarray(Image.open(out)), [line for line in done.stderr.splitlines() if line.startswith("note:")]


@pytest.fixture(scope="module")
def reference(files, tmp_path_factory):
    """The pixels with the files as they were written, and no note."""
    place = tmp_path_factory.mktemp("good")
    for f in files.glob("rtcli-*"):
        shutil.copy2(f, place)
    pixels, notes = render(place, place / "good.png")
    assert notes == []
    return pixels


def planted_library(place: Path, marker: Path) -> Path:
    """A library whose constructor writes `marker`, put in place of the integrator's."""
    source = place.parent / f"{place.name}-planted.c"
    source.write_text(PLANTED.format(marker=marker))
    about = json.loads(machinecode.description_file(fast.ENTRY, place).read_text())
    library = place / about["library"]
    subprocess.run([*writing.compiler(), "-shared", "-fPIC", "-o", str(library), str(source)], check=True)
    return library


def recorded(place: Path, library: Path) -> None:
    """The description names `library` with its SHA-256, as if rtcli had written it."""
    about = machinecode.description_file(fast.ENTRY, place)
    description = json.loads(about.read_text())
    description["sha256"] = hashlib.sha256(library.read_bytes()).hexdigest()
    about.write_text(json.dumps(description))


def fifo(path: Path) -> None:
    path.unlink()
    os.mkfifo(path)


def other_owner(path: Path) -> None:
    os.chown(path, 65534, 65534)


def truncated(library: Path) -> None:
    code = library.read_bytes()
    library.write_bytes(code[:len(code) // 2])


CASES = {                                # what is done to the copy of the files; what the note says
    "a planted library": (lambda place, library, about, marker: planted_library(place, marker),
                          "does not have the SHA-256 recorded when it was written"),
    "a planted library, recorded, of another user": (
        lambda place, library, about, marker: (recorded(place, planted_library(place, marker)),
                                               other_owner(library)), "belongs to another user (uid 65534)"),
    "a planted library, recorded, in a folder of another user": (
        lambda place, library, about, marker: (recorded(place, planted_library(place, marker)),
                                               other_owner(place)), "belongs to another user (uid 65534)"),
    "a planted library, recorded, in a folder anyone may write": (
        lambda place, library, about, marker: (recorded(place, planted_library(place, marker)),
                                               place.chmod(0o1777)), "is writable by other users"),
    "a truncated library": (lambda place, library, about, marker: truncated(library),
                            "does not have the SHA-256 recorded when it was written"),
    "a truncated library, recorded": (lambda place, library, about, marker: (truncated(library),
                                                                             recorded(place, library)),
                                      "is cut short"),
    "a FIFO for the library": (lambda place, library, about, marker: fifo(library), "is not a regular file"),
    "a FIFO for the description": (lambda place, library, about, marker: fifo(about), "is not a regular file"),
    "a description naming a helper": (
        lambda place, library, about, marker: about.write_text(about.read_text().replace(
            f'"symbol": "{places.ENTRY_SYMBOL}"', '"symbol": "numba_do_raise"')), "names 'numba_do_raise'"),
}


@pytest.mark.parametrize("case", CASES)
def test_a_hostile_file_falls_back_to_numba_with_the_same_pixels(files, reference, tmp_path, case):
    place, marker = tmp_path / "cache", tmp_path / "marker"
    place.mkdir(mode=0o700)
    for f in files.glob("rtcli-*"):
        shutil.copy2(f, place)
    about = machinecode.description_file(fast.ENTRY, place)
    change, said = CASES[case]
    change(place, place / json.loads(about.read_text())["library"], about, marker)
    pixels, notes = render(place, tmp_path / "out.png")
    assert np.array_equal(pixels, reference)
    assert not marker.exists()
    assert len(notes) == 1 and notes[0].startswith("note: machine code file not used, numba's path instead: ")
    assert said in notes[0], notes
