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
from rtcli.rendering.tiles import Job, render_tile
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
    assert machinecode.make("small", body, args, results=2) is None
    return body


def test_a_file_gives_the_numbers_numba_gives(small):
    entry = machinecode.load("small")
    pair, out, k, x, flag = small_args()
    assert entry.fits((pair, out, k, x, flag))
    assert entry(pair, out, k, x, flag) == (4, 4)
    reference = np.zeros(4)
    small(pair, reference, k, x, flag)
    assert np.array_equal(out, reference) and out[1] == 1 * 2.5 + 1.5 + 1.0


def test_arrays_that_cannot_be_passed_by_address_do_not_fit(small):
    """The C function writes where the caller reads: a strided or misaligned array (which would
    need a copy) goes to numba instead."""
    entry = machinecode.load("small")
    pair, out, k, x, flag = small_args()
    strided = np.zeros(8)[::2]
    assert not entry.fits((pair, strided, k, x, flag))
    assert not entry.fits((Pair(np.arange(8.0)[::2], 2.5), out, k, x, flag))
    assert machinecode.entry("small", lambda: "numba's", (pair, strided, k, x, flag)) == "numba's"
    assert entry.fits((pair, out, k, x, flag))


def test_arguments_of_another_layout_do_not_fit(small):
    entry = machinecode.load("small")
    pair, out, k, x, flag = small_args()
    assert not entry.fits((pair, out, k, 1, flag))               # an int where a float was
    assert not entry.fits((pair, out.reshape(2, 2), k, x, flag))  # two dimensions
    assert not entry.fits((pair, out.astype(np.float32), k, x, flag))
    assert not entry.fits((pair, out, np.int32(k), x, flag))        # numba would type it int32
    assert not entry.fits((pair, out, k, np.float32(x), flag))
    assert not entry.fits((pair, out, k, x))
    assert machinecode.entry("small", lambda: "numba's", (pair, out, k, 1, flag)) == "numba's"
    assert machinecode.entry("small", lambda: "numba's", (pair, out, k, x, flag)) is entry


def edit_description(place, name, change):
    about = machinecode.description_file(name, place)
    description = json.loads(about.read_text())
    change(description)
    about.write_text(json.dumps(description))
    machinecode._loaded.clear()


@pytest.mark.parametrize("field, value", [("sources", "0" * 64), ("cpu", "another-cpu"), ("numba", "0.1"),
                                          ("llvmlite", "0.1"), ("python", "cpython-27"), ("platform", "win32")])
def test_a_file_made_for_another_process_is_not_used(small, place, field, value):
    assert machinecode.load("small") is not None
    edit_description(place, "small", lambda d: d["key"].update({field: value}))
    assert machinecode.load("small") is None


def test_the_cpu_is_told_by_its_model_and_flags():
    info = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 9B14\nflags\t\t: fpu sse2 avx2{}\n\n" \
           "processor\t: 1\n"
    plain, wide = machinecode.cpu(info.format("")), machinecode.cpu(info.format(" avx512f"))
    assert plain.startswith("cpuinfo ") and plain != wide                 # another CPU: another key
    assert machinecode.cpu(info.format("")) == plain
    if os.path.exists("/proc/cpuinfo"):
        assert machinecode.cpu().startswith("cpuinfo ")                    # read, not the fallback


def test_a_library_with_a_symbol_the_process_lacks_is_not_used(small, place, tmp_path):
    """Opened with every symbol bound: one the process does not have means numba's path."""
    cc = machinecode.compiler()
    source = tmp_path / "lacks.c"
    source.write_text("extern void rtcli_no_such_symbol(void);\nvoid lacks(void) { rtcli_no_such_symbol(); }\n")
    library = place / "rtcli-small-lacks.so"
    subprocess.run([*cc, "-shared", "-fPIC", "-o", str(library), str(source)], check=True)
    edit_description(place, "small", lambda d: d.update(library=library.name, symbol="lacks"))
    assert machinecode.load("small") is None


def test_a_missing_or_broken_file_is_not_used(small, place):
    about = machinecode.description_file("small", place)
    edit_description(place, "small", lambda d: d.update(library="rtcli-small-0000.so"))   # a pair half written
    assert machinecode.load("small") is None
    about.write_text("{")
    machinecode._loaded.clear()
    assert machinecode.load("small") is None
    about.unlink()
    machinecode._loaded.clear()
    assert machinecode.load("small") is None
    assert machinecode.load("never-made") is None


def test_without_a_cache_a_c_compiler_or_the_switch_nothing_is_made(monkeypatch, place):
    from numba import njit
    body = njit(small_body)
    body(*small_args())
    monkeypatch.setenv("CC", "false")
    assert machinecode.make("small", body, small_args(), results=2).startswith("the C compiler failed")
    monkeypatch.setattr(machinecode, "compiler", lambda: None)
    assert machinecode.make("small", body, small_args(), results=2) == "no C compiler (cc) to link them"
    monkeypatch.setattr(machinecode, "ENABLED", False)
    assert machinecode.make("small", body, small_args(), results=2) == "RTCLI_MACHINE_CODE=0"
    assert machinecode.load("small") is None
    monkeypatch.setattr(machinecode, "ENABLED", True)
    monkeypatch.setattr(machinecode, "folder", lambda: None)
    assert machinecode.make("small", body, small_args(), results=2) == "no cache folder"
    assert machinecode.load("small") is None
    assert not list(place.iterdir())                                   # nothing left behind


def test_a_second_file_replaces_the_first_whole(small, place):
    """The library's name holds its hash and the description names it: writing again leaves one
    consistent pair, and a process that opened the old one keeps it."""
    first = machinecode.load("small")
    assert machinecode.make("small", small, small_args(), results=2) is None
    libraries = list(place.glob("rtcli-small-*.so"))
    assert len(libraries) == 1 and json.loads(machinecode.description_file("small", place).read_text())[
        "library"] == libraries[0].name
    assert machinecode.load("small")(*small_args()) == (4, 4) and first(*small_args()) == (4, 4)


ERROR_PATH = """
import sys
import numpy as np
from numba import njit
from rtcli import machinecode
sys.path.insert(0, {here!r})
from test_machinecode import Pair

@njit(error_model="numpy")
def raising(pair, out, k, x, flag):
    if k > 5:
        raise ValueError("a path rtcli's kernels never take")
    out[0] = x
    return 0, 0

machinecode.folder = lambda: __import__("pathlib").Path({place!r})
args = (Pair(np.arange(4.0), 1.0), np.zeros(4), 1, 0.5, True)
raising(*args)
assert machinecode.make("raising", raising, args, results=2) is None
del sys.modules["numba"]
entry = machinecode.load("raising")
entry(*args)
print("fine", flush=True)
entry(args[0], args[1], 9, 0.5, True)
print("not reached", flush=True)
"""


def test_the_error_path_says_so_and_stops_the_process(place):
    code = ERROR_PATH.format(here=str(Path(__file__).parent), place=str(place))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert done.stdout.split() == ["fine"], done.stderr
    assert done.returncode != 0 and "RTCLI_MACHINE_CODE=0" in done.stderr


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
    made, why = machine_code(fast.choose(_scenes()[0], "compiled", notes=lambda text: None))
    assert made == [fast.ENTRY, bvh_build.LEVELS], why
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
    found = sorted(p.name.rsplit("-", 1)[0] for p in copy.glob("rtcli-*.so"))
    assert found == ["rtcli-levels", "rtcli-trace_camera"]
    old = fast.cache_places
    try:
        fast.cache_places = lambda: [([copy], False)]
        fast.drop_stale_cache()
    finally:
        fast.cache_places = old
    assert not list(copy.glob("rtcli-*.so")) and not list(copy.glob("rtcli-*.json"))
    assert machinecode.description_file(fast.ENTRY, folder).exists()     # the real cache untouched
