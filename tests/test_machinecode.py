"""Machine code files (rtcli/machinecode.py): the compiled entry points run without numba give
numba's numbers, and a file is used only by a process it was made for."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

from rtcli import compiled as fast
from rtcli import machinecode, variants
from rtcli.core import bvh_build
from rtcli.render import Job, render_tile
from rtcli.scenefile.build import load_scene

pytestmark = pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")

ROOT = Path(__file__).resolve().parent.parent
Pair = namedtuple("Pair", "values scale")


def small_body(pair, out, k, x, flag):
    """A tiny entry: every kind of argument, and results."""
    for i in range(len(out)):
        out[i] = pair.values[i] * pair.scale + k * x + (1.0 if flag else 0.0)
    return len(out), k + 1


@pytest.fixture
def place(tmp_path, monkeypatch):
    """Machine code files made and read in a folder of their own."""
    monkeypatch.setattr(machinecode, "folder", lambda: tmp_path)
    monkeypatch.setattr(machinecode, "_loaded", {})
    return tmp_path


def small_args():
    return Pair(np.arange(4.0), 2.5), np.zeros(4), 3, 0.5, True


@pytest.fixture
def small(place):
    """The tiny entry's machine code file, made by numba."""
    from numba import njit
    body = njit(small_body)
    args = small_args()
    body(*args)
    assert machinecode.make("small", body, args, results=2)
    return body


def test_a_file_gives_the_numbers_numba_gives(small):
    entry = machinecode.load("small")
    pair, out, k, x, flag = small_args()
    assert entry.fits((pair, out, k, x, flag))
    assert entry(pair, out, k, x, flag) == (4, 4)
    reference = np.zeros(4)
    small(pair, reference, k, x, flag)
    assert np.array_equal(out, reference) and out[1] == 1 * 2.5 + 1.5 + 1.0


def test_arrays_are_passed_in_c_order(small):
    entry = machinecode.load("small")
    values = np.arange(8.0)[::2]                       # not contiguous: passed as a contiguous copy
    out = np.zeros(4)
    entry(Pair(values, 1.0), out, 0, 0.0, False)
    assert np.array_equal(out, values)


def test_arguments_of_another_layout_do_not_fit(small):
    entry = machinecode.load("small")
    pair, out, k, x, flag = small_args()
    assert not entry.fits((pair, out, k, 1, flag))               # an int where a float was
    assert not entry.fits((pair, out.reshape(2, 2), k, x, flag))  # two dimensions
    assert not entry.fits((pair, out.astype(np.float32), k, x, flag))
    assert not entry.fits((pair, out, k, x))
    assert machinecode.entry("small", lambda: "numba's", (pair, out, k, 1, flag)) == "numba's"
    assert machinecode.entry("small", lambda: "numba's", (pair, out, k, x, flag)) is entry


def edit_description(place, name, change):
    about = machinecode.files(name, place)[1]
    description = json.loads(about.read_text())
    change(description)
    about.write_text(json.dumps(description))
    machinecode._loaded.clear()


@pytest.mark.parametrize("field, value", [("sources", "0" * 64), ("cpu", "another-cpu"), ("format", 0),
                                          ("python", "cpython-27"), ("platform", "win32")])
def test_a_file_made_for_another_process_is_not_used(small, place, field, value):
    assert machinecode.load("small") is not None
    edit_description(place, "small", lambda d: d["key"].update({field: value}))
    assert machinecode.load("small") is None


def test_a_file_whose_code_imports_a_missing_symbol_is_not_used(small, place):
    edit_description(place, "small", lambda d: d["imports"].append("rtcli_no_such_symbol"))
    assert machinecode.load("small") is None


def test_a_missing_or_broken_file_is_not_used(small, place):
    code, about = machinecode.files("small", place)
    about.write_text("{")
    machinecode._loaded.clear()
    assert machinecode.load("small") is None
    about.unlink()
    machinecode._loaded.clear()
    assert machinecode.load("small") is None
    assert machinecode.load("never-made") is None


def test_without_a_cache_or_a_c_compiler_nothing_is_made(monkeypatch, place):
    monkeypatch.setattr(machinecode, "compiler", lambda: None)
    assert not machinecode.make("small", None, small_args())
    monkeypatch.undo()
    monkeypatch.setattr(machinecode, "folder", lambda: None)
    monkeypatch.setattr(machinecode, "_loaded", {})
    assert not machinecode.make("small", None, small_args())
    assert machinecode.load("small") is None


def test_the_wrapper_rebuilds_each_kind_of_argument():
    source, tuples = machinecode.wrapper_source(
        [(machinecode.layout(a), machinecode._classes(a)) for a in small_args()], 2)
    assert "T0(carray(pointer(w[0], Dfloat64), (w[1], )), f[0])" in source     # the namedtuple
    assert "carray(pointer(w[2], Dfloat64), (w[3], ))" in source                # out
    assert "w[4], f[1], w[5] != 0)" in source                                    # int, float, bool
    assert "r[1] = got[1]" in source and tuples[0][0] is Pair


# --- the engine's own entries ---
@pytest.fixture(scope="module")
def engine_files():
    """The integrator's and the BVH build's files, beside numba's cache (made if missing)."""
    if machinecode.folder() is None:
        pytest.skip("no cache folder")
    from rtcli.compiled.warmup import _scenes, machine_code
    machinecode._loaded.clear()
    made = machine_code(fast.choose(_scenes()[0], "compiled", notes=lambda text: None))
    assert made == [fast.ENTRY, bvh_build.LEVELS], "numba's code library could not be written out"
    return made


SCENES = ["whitted", "csg", "bubble", "textures", "teapot", "inspect"]


@pytest.mark.parametrize("name", SCENES)
def test_the_integrators_file_gives_numbas_pixels(engine_files, name):
    scene = load_scene(str(ROOT / "scenes" / f"{name}.yaml"))
    engine = fast.choose(scene, "compiled")
    assert engine.entry is not None                      # from the file
    job = Job(64, 48, engine="compiled")
    i, j = np.meshgrid(np.arange(64), np.arange(48))
    from_file, counts_file = render_tile(scene, job, i.ravel(), j.ravel(), engine)
    engine.entry = None                                  # numba's dispatcher
    from_numba, counts_numba = render_tile(scene, job, i.ravel(), j.ravel(), engine)
    assert np.array_equal(from_file, from_numba) and counts_file == counts_numba
    assert from_file.std() > 0.01                        # a picture, not a blank


def test_the_bvh_builds_file_builds_the_reference_tree(engine_files):
    from bvh_reference import build as reference_build
    lo = np.random.default_rng(5).normal(size=(3000, 3))
    hi = lo + np.random.default_rng(6).uniform(0, 0.2, size=(3000, 3))
    entry = machinecode.load(bvh_build.LEVELS)
    assert entry is not None and entry.fits(bvh_build.levels_args(lo, hi, 2, 12))
    tree = bvh_build.compiled_build(lo, hi, 2, 12, variant=entry)
    for got, want in zip(tree, reference_build(lo, hi, 2, 12)):
        assert np.array_equal(got, want)


def test_a_render_with_the_files_does_not_load_numba(engine_files, tmp_path):
    code = ("import sys, rtcli; img = rtcli.render(sys.argv[1], width=48, height=36); "
            "print(img.stats.engine, 'numba' in sys.modules)")
    for scene in ("whitted", "teapot"):
        done = subprocess.run([sys.executable, "-c", code, str(ROOT / "scenes" / f"{scene}.yaml")],
                              capture_output=True, text=True, cwd=tmp_path, timeout=120)
        assert done.returncode == 0, done.stderr
        assert done.stdout.split() == ["compiled", "False"], (scene, done.stdout, done.stderr)


def test_stale_sources_drop_the_files(engine_files, tmp_path):
    """drop_stale_cache deletes the files with numba's, in a copy of the cache whose sources
    fingerprint no longer matches."""
    folder = machinecode.folder()
    copy = tmp_path / "compiled"
    shutil.copytree(folder, copy)
    (copy / fast.STAMP).write_text("stale")
    found = sorted(p.name for p in copy.glob("rtcli-*.so"))
    assert found == ["rtcli-levels.so", "rtcli-trace_camera.so"]
    old = fast.cache_places
    try:
        fast.cache_places = lambda: [([copy], False)]
        fast.drop_stale_cache()
    finally:
        fast.cache_places = old
    assert not list(copy.glob("rtcli-*.so")) and not list(copy.glob("rtcli-*.json"))
    assert os.path.exists(machinecode.files(fast.ENTRY, folder)[0])      # the real cache untouched
