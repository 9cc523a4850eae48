"""Machine code files (rtcli/kernels/machinecode): the compiled entry points run without numba give
numba's numbers, and a file is used only by a process it was made for."""

from __future__ import annotations

import hashlib
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
from rtcli.compiled import build as compiled_build
from rtcli.core import bvh_build
from rtcli.kernels import machinecode, numba_cache, variants
from rtcli.kernels.machinecode import arguments, entries, flow, llvmir, places, trust, writing
from rtcli.rendering.engine import choose
from rtcli.rendering.tiles import Job, render_tile
from rtcli.scenefile.load import load_scene

pytestmark = pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")

ROOT = Path(__file__).resolve().parents[2]
Pair = namedtuple("Pair", "values scale")


def small_body(pair, out, k, x, flag):
    """A tiny entry: every kind of argument, and results."""
    for i in range(len(out)):
        out[i] = pair.values[i] * pair.scale + k * x + (1.0 if flag else 0.0)
    return len(out), k + 1


@pytest.fixture
def place(tmp_path, monkeypatch):
    """Machine code files made and read in a folder of their own."""
    monkeypatch.setattr(places, "folder", lambda: tmp_path)
    monkeypatch.setattr(entries, "_loaded", {})
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
    entries._loaded.clear()


@pytest.mark.parametrize("field, value", [("sources", "0" * 64), ("cpu", "another-cpu"), ("numba", "0.1"),
                                          ("llvmlite", "0.1"), ("python", "cpython-27"), ("platform", "win32")])
def test_a_file_made_for_another_process_is_not_used(small, place, field, value):
    assert machinecode.load("small") is not None
    edit_description(place, "small", lambda d: d["key"].update({field: value}))
    assert machinecode.load("small") is None


def test_the_switch_leaves_a_file_unused(small, monkeypatch):
    """RTCLI_MACHINE_CODE=0: a file made for this process is not loaded, and none is written."""
    assert machinecode.load("small") is not None
    monkeypatch.setattr(places, "ENABLED", False)
    entries._loaded.clear()
    assert machinecode.load("small") is None
    assert machinecode.make("small", small, small_args(), results=2) == "RTCLI_MACHINE_CODE=0"


def test_the_key_covers_every_file_of_this_package(tmp_path):
    """The machine code is made by this package too (the wrapper, the stubs, the checks): a
    change to any of its files is another key."""
    copy = tmp_path / places.HERE.name
    shutil.copytree(places.HERE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    digest = places.sources_digest(tmp_path, (copy.name,))
    assert places.key()["sources"] == places.sources_digest() + digest[:16]
    files = sorted(copy.glob("*.py"))
    assert {f.name for f in files} >= {"__init__.py", "entries.py", "places.py", "writing.py"}
    for f in files:
        kept = f.read_bytes()
        f.write_bytes(kept + b"\n")
        assert places.sources_digest(tmp_path, (copy.name,)) != digest, f.name
        f.write_bytes(kept)


def test_the_cpu_is_told_by_its_model_and_flags():
    info = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 9B14\nflags\t\t: fpu sse2 avx2{}\n\n" \
           "processor\t: 1\n"
    plain, wide = places.cpu(info.format("")), places.cpu(info.format(" avx512f"))
    assert plain.startswith("cpuinfo ") and plain != wide                 # another CPU: another key
    assert places.cpu(info.format("")) == plain
    if os.path.exists("/proc/cpuinfo"):
        assert places.cpu().startswith("cpuinfo ")                    # read, not the fallback


def put_library(place, name, code: bytes, **changes) -> Path:
    """Put `code` in place as the library of `name`, its description naming it with its SHA-256
    (a pair as make writes it), then `changes` to the description."""
    library = place / f"rtcli-{name}-{hashlib.sha256(code).hexdigest()[:16]}.so"
    library.write_bytes(code)
    edit_description(place, name, lambda d: d.update(library=library.name, sha256=hashlib.sha256(code).hexdigest(),
                                                      **changes))
    return library


@pytest.fixture
def build(tmp_path_factory):
    """compile(source): a shared library compiled from C source by the C compiler, as bytes."""
    def compile_c(source: str) -> bytes:
        work = tmp_path_factory.mktemp("c")
        c, library = work / "library.c", work / "library.so"
        c.write_text(source)
        subprocess.run([*writing.compiler(), "-shared", "-fPIC", "-o", str(library), str(c)], check=True)
        return library.read_bytes()
    return compile_c


def test_a_library_with_a_symbol_the_process_lacks_is_not_used(small, place, build):
    """Opened with every symbol bound: one the process does not have means numba's path."""
    put_library(place, "small", build("extern void rtcli_no_such_symbol(void);\n"
                                      "int rtcli_entry(void) { rtcli_no_such_symbol(); return 0; }\n"))
    assert machinecode.load("small") is None


def test_a_missing_or_broken_file_is_not_used(small, place):
    about = machinecode.description_file("small", place)
    edit_description(place, "small", lambda d: d.update(library="rtcli-small-0000.so"))   # a pair half written
    assert machinecode.load("small") is None
    about.write_text("{")
    entries._loaded.clear()
    assert machinecode.load("small") is None
    about.unlink()
    entries._loaded.clear()
    assert machinecode.load("small") is None
    assert machinecode.load("never-made") is None


# --- trust: a file is opened only when this user wrote it (docs/architecture.md) ---
PLANTED = """#include <stdio.h>
__attribute__((constructor)) static void planted(void) {{
    FILE *f = fopen("{marker}", "w");
    if (f) {{ fputs("ran", f); fclose(f); }}
}}
int rtcli_entry(void *words, void *floats, void *results) {{ return 0; }}
"""


@pytest.fixture
def planted(small, build, tmp_path_factory):
    """A library whose constructor, run when it is opened, writes a marker file: (its bytes, the marker)."""
    marker = tmp_path_factory.mktemp("marker") / "ran"
    return build(PLANTED.format(marker=marker)), marker


@pytest.fixture
def notes():
    """What load says about the files it does not use."""
    heard = []
    machinecode.report_to(heard.append)
    entries._told.clear()
    yield heard
    machinecode.report_to(None)


def test_a_planted_library_runs_only_when_every_check_passes(place, planted):
    """The marker works: a library this user wrote and recorded is opened, constructor and all
    (so the tests below, where it never appears, can fail)."""
    code, marker = planted
    put_library(place, "small", code)
    assert machinecode.load("small") is not None and marker.read_text() == "ran"


def test_a_library_planted_under_the_expected_name_never_runs(place, planted, notes):
    code, marker = planted
    library = place / json.loads(machinecode.description_file("small", place).read_text())["library"]
    library.write_bytes(code)
    assert machinecode.load("small") is None and not marker.exists()
    assert notes == [(f"machine code file not used, numba's path instead: {library.name} does not have the "
                      "SHA-256 recorded when it was written")]


def chown(path, uid=65534):
    os.chown(path, uid, uid, follow_symlinks=False)


def moved_away(path):
    """`path` replaced by a link to the same bytes elsewhere."""
    away = path.parent.parent / f"away-{path.name}"
    path.rename(away)
    path.symlink_to(away)


OTHERS = {                    # what is done to the library, its description or their folder; what load says
    "library of another user": (lambda lib, about, place: chown(lib), "belongs to another user (uid 65534)"),
    "library writable by others": (lambda lib, about, place: lib.chmod(0o666), "is writable by other users"),
    "library writable by its group": (lambda lib, about, place: lib.chmod(0o664), "is writable by other users"),
    "description of another user": (lambda lib, about, place: chown(about), "belongs to another user"),
    "description writable by others": (lambda lib, about, place: about.chmod(0o646), "is writable by other users"),
    "folder of another user": (lambda lib, about, place: chown(place), "belongs to another user"),
    "folder writable by others": (lambda lib, about, place: place.chmod(0o777), "is writable by other users"),
    "folder writable by its group": (lambda lib, about, place: place.chmod(0o770), "is writable by other users"),
    "library a link": (lambda lib, about, place: moved_away(lib), "is not a regular file"),
    "description a link": (lambda lib, about, place: moved_away(about), "is not a regular file"),
}


@pytest.mark.parametrize("case", OTHERS)
def test_a_file_anyone_else_could_have_written_is_never_opened(place, planted, notes, case):
    """Even with the SHA-256 of its description: the owner, the modes and the kind of file are
    checked first, and the constructor never runs."""
    code, marker = planted
    library = put_library(place, "small", code)
    change, said = OTHERS[case]
    change(library, machinecode.description_file("small", place), place)
    assert machinecode.load("small") is None and not marker.exists()
    assert len(notes) == 1 and said in notes[0], notes


def test_without_memory_files_a_private_copy_is_opened_and_removed(small, monkeypatch, tmp_path_factory):
    """Where there is no memfd (macOS), the checked bytes are opened from a copy in a new 0700
    folder, removed once open."""
    monkeypatch.delattr(os, "memfd_create")
    private = tmp_path_factory.mktemp("tmp")
    monkeypatch.setattr(trust.tempfile, "tempdir", str(private))
    kept = len(trust._kept)
    assert machinecode.load("small")(*small_args()) == (4, 4)
    assert len(trust._kept) == kept and list(private.iterdir()) == []


def test_a_folder_that_is_a_link_to_this_users_folder_is_followed(small, place, tmp_path_factory, monkeypatch):
    """The cache folder may be reached through a link (NUMBA_CACHE_DIR often is one): what is
    checked is the folder it leads to."""
    link = tmp_path_factory.mktemp("link") / "cache"
    link.symlink_to(place)
    monkeypatch.setattr(places, "folder", lambda: link)
    entries._loaded.clear()
    assert machinecode.load("small")(*small_args()) == (4, 4)


LOAD_ALONE = """
import sys
from pathlib import Path
from rtcli.kernels import machinecode
from rtcli.kernels.machinecode import places
places.folder = lambda: Path(sys.argv[1])
machinecode.report_to(print)
print(machinecode.load("small"))
"""


def load_alone(place) -> list[str]:
    """What load prints in a process of its own, which a crash or a hang cannot take the tests with."""
    done = subprocess.run([sys.executable, "-c", LOAD_ALONE, str(place)], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_a_truncated_or_corrupted_library_never_crashes(small, place):
    """Cut in half (SIGBUS when mapped), with or without its description's SHA-256 updated, or a
    byte changed: never opened."""
    library = place / json.loads(machinecode.description_file("small", place).read_text())["library"]
    code = library.read_bytes()
    library.write_bytes(code[:len(code) // 2])
    assert load_alone(place)[-1:] == ["None"]
    put_library(place, "small", code[:len(code) // 2])
    lines = load_alone(place)
    assert lines[-1] == "None" and lines[0].endswith("is cut short")
    put_library(place, "small", code[:40])
    assert load_alone(place)[0].endswith("is cut short")
    changed = bytearray(code)
    changed[len(code) // 2] ^= 0xFF
    library.write_bytes(bytes(changed))
    edit_description(place, "small", lambda d: d.update(library=library.name, sha256=hashlib.sha256(code).hexdigest()))
    lines = load_alone(place)
    assert lines == [(f"machine code file not used, numba's path instead: {library.name} does not have the "
                      "SHA-256 recorded when it was written"), "None"]
    assert trust.cut_short(code) is False


@pytest.mark.parametrize("which", ["library", "description"])
def test_a_fifo_in_place_of_a_file_does_not_hang(small, place, which):
    about = machinecode.description_file("small", place)
    target = place / json.loads(about.read_text())["library"] if which == "library" else about
    target.unlink()
    os.mkfifo(target)
    lines = load_alone(place)                   # within load_alone's timeout
    assert lines == [f"machine code file not used, numba's path instead: {target.name} is not a regular file",
                     "None"]
    with pytest.raises(OSError):                # and no one left reading it
        os.close(os.open(target, os.O_WRONLY | os.O_NONBLOCK))


@pytest.mark.parametrize("symbol", ["numba_do_raise", "NRT_MemInfo_alloc", "NRT_decref", "abort",
                                    writing.BODY_SYMBOL])
def test_a_description_naming_a_helper_as_its_entry_is_refused(small, place, notes, symbol):
    """Only rtcli's C function is ever called: not one of numba's helpers (or their stubs), nor a
    function of the C library the library links to."""
    edit_description(place, "small", lambda d: d.update(symbol=symbol))
    assert machinecode.load("small") is None
    assert notes == [(f"machine code file not used, numba's path instead: rtcli-small.json names {symbol!r} as "
                      f"its entry, not {places.ENTRY_SYMBOL}")]


def test_the_files_are_written_for_this_user_alone_whatever_the_umask(place):
    from numba import njit
    body = njit(small_body)
    body(*small_args())
    old = os.umask(0o002)
    try:
        assert machinecode.make("small", body, small_args(), results=2) is None
    finally:
        os.umask(old)
    for f in place.glob("rtcli-small*"):
        assert f.stat().st_mode & 0o777 == 0o644, f
    assert machinecode.load("small")(*small_args()) == (4, 4)


def test_nothing_is_written_to_a_folder_anyone_else_could_write(place):
    from numba import njit
    body = njit(small_body)
    body(*small_args())
    place.chmod(0o777)
    assert "is writable by other users" in machinecode.make("small", body, small_args(), results=2)
    assert not list(place.iterdir())


def test_rtcli_makes_its_cache_folders_for_this_user_alone(tmp_path):
    old = os.umask(0o002)
    try:
        root = tmp_path / "cache" / "rtcli"
        assert numba_cache.writable(str(root))
        location = numba_cache._private_location(numba_cache.CacheLocation(str(root), "test"))
    finally:
        os.umask(old)
    made = [tmp_path / "cache", root, *map(Path, location.folders())]
    assert [f.stat().st_mode & 0o777 for f in made] == [0o700] * len(made)
    assert tmp_path.stat().st_mode & 0o777 == 0o700        # pytest's, left as it was


def test_without_a_cache_a_c_compiler_or_the_switch_nothing_is_made(monkeypatch, place):
    from numba import njit
    body = njit(small_body)
    body(*small_args())
    monkeypatch.setenv("CC", "false")
    assert machinecode.make("small", body, small_args(), results=2).startswith("the C compiler failed")
    monkeypatch.setattr(writing, "compiler", lambda: None)
    assert machinecode.make("small", body, small_args(), results=2) == "no C compiler (cc) to link them"
    monkeypatch.setattr(places, "ENABLED", False)
    assert machinecode.make("small", body, small_args(), results=2) == "RTCLI_MACHINE_CODE=0"
    assert machinecode.load("small") is None
    monkeypatch.setattr(places, "ENABLED", True)
    monkeypatch.setattr(places, "folder", lambda: None)
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
    again = machinecode.load("small")
    assert again is not first                                          # the new pair is read, not the old kept
    assert again(*small_args()) == (4, 4) and first(*small_args()) == (4, 4)


ERROR_PATH = """
import sys
import numpy as np
from numba import njit
from rtcli.kernels import machinecode
from rtcli.kernels.machinecode import places
sys.path.insert(0, {here!r})
from test_machinecode import Pair

@njit(error_model="numpy")
def raising(pair, out, k, x, flag):
    if k > 5:
        raise ValueError("a path rtcli's kernels never take")
    out[0] = x
    return 0, 0

places.folder = lambda: __import__("pathlib").Path({place!r})
args = (Pair(np.arange(4.0), 1.0), np.zeros(4), 1, 0.5, True)
raising(*args)
assert machinecode.make("raising", raising, args, results=2) is None
del sys.modules["numba"]
entry = machinecode.load("raising")
print(entry(*args), flush=True)
try:
    entry(args[0], args[1], 9, 0.5, True)
except machinecode.Stopped as e:
    print("stopped:", e, flush=True)
print(entry(*args), args[1][0], flush=True)
"""


def test_the_error_path_stops_the_call_not_the_process(place):
    """The helpers on numba's error paths are stubs that leave the machine code at once: the call
    raises Stopped in Python, and the process (a Jupyter kernel, a Dask worker) goes on."""
    code = ERROR_PATH.format(here=str(Path(__file__).parent), place=str(place))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=ROOT,
                          check=False)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "(0, 0)" and lines[2] == "(0, 0) 0.5", done.stdout
    assert lines[1].startswith("stopped: ") and "RTCLI_MACHINE_CODE=0" in lines[1]


def allocating(pair, out, k, x, flag):
    scratch = np.empty(k)                   # numba's runtime allocates it, on every call
    scratch[:] = x
    out[0] = scratch.sum()
    return 0, 0


def printing(pair, out, k, x, flag):
    if flag:
        print(k)                            # Python's C API, on a path that raises nothing
    return 0, 0


@pytest.mark.parametrize("body, helper", [(allocating, "NRT_MemInfo_alloc"), (printing, "numba_gil_ensure")])
def test_a_library_that_would_call_numbas_helpers_is_refused_when_written(place, body, helper):
    from numba import njit
    compiled = njit(body)
    compiled(*small_args())
    why = machinecode.make("small", compiled, small_args(), results=2)
    assert why.startswith(f"refused: it would call {helper}") and f"{body.__name__}" in why
    assert not list(place.iterdir())                               # nothing written


# --- which helpers a call can reach: helper_calls on small modules ---
MODULE = """
define i32 @raiser(ptr %retptr, ptr %excinfo) {{
entry:
  %p = call ptr @NRT_MemInfo_alloc(i64 8)
  {raiser_returns}
}}

define {inner_range} i32 @inner(ptr %retptr, ptr %excinfo, i64 %k) {{
entry:
  %c = icmp sgt i64 %k, 5
  br i1 %c, label %bad, label %good

bad:                                              ; preds = %entry
  %s = call i32 @raiser(ptr %retptr, ptr %excinfo)
  br label %common.ret

good:                                             ; preds = %entry
  {good}
  br label %common.ret

common.ret:                                       ; preds = %good, %bad
  %status = phi i32 [ {bad_status}, %bad ], [ 0, %good ]
  ret i32 %status
}}

define ptr @root(i64 %k) {{
entry:
  %r = alloca ptr, align 8
  %e = alloca ptr, align 8
  %s = call i32 @inner(ptr %r, ptr %e, i64 %k)
  {check}

failed:                                           ; preds = %entry
  call void @numba_gil_ensure(ptr nonnull %r)
  call void @PyErr_SetString(ptr @PyExc_RuntimeError, ptr null)
  br label %done

done:                                             ; preds = %entry, %failed
  ret ptr null
}}

declare ptr @NRT_MemInfo_alloc(i64) local_unnamed_addr
declare void @numba_gil_ensure(ptr) local_unnamed_addr
declare void @PyErr_SetString(ptr, ptr) local_unnamed_addr
@PyExc_RuntimeError = external global i8
"""
RAISING = {"raiser_returns": "ret i32 1", "inner_range": "range(i32 -1, -2)", "good": "%x = add i64 %k, 1",
           "bad_status": "1", "check": "%ok = icmp eq i32 %s, 0\n  br i1 %ok, label %done, label %failed, !prof !0"}
SWITCH = "switch i32 %s, label %failed [\n    i32 0, label %done\n{more}  ]"


GIL_ENSURE = [("root", "numba_gil_ensure"), ("root", "PyErr_SetString"), ("root", "PyExc_RuntimeError")]


@pytest.mark.parametrize("change, found", [
    ({}, []),
    ({"bad_status": "%s"}, []),                                # the raiser's status passed on as it is
    ({"good": "%q = call ptr @NRT_MemInfo_alloc(i64 8)"}, [("inner", "NRT_MemInfo_alloc")]),     # on every call
    ({"raiser_returns": "ret i32 0", "bad_status": "%s"}, [("raiser", "NRT_MemInfo_alloc")]),   # it returns: no error
    ({"bad_status": "0"}, [("raiser", "NRT_MemInfo_alloc")]),    # the raiser's error swallowed: the call goes on
    ({"inner_range": ""}, GIL_ENSURE + [("raiser", "NRT_MemInfo_alloc")]),   # -2 (None returned) may fail that test
    ({"check": RAISING["check"].replace("eq", "ne")}, GIL_ENSURE),  # the branch of a call that returned
    ({"inner_range": "", "check": SWITCH.format(more="    i32 -2, label %done\n")}, []),     # numba's own test
    ({"check": SWITCH.format(more="")}, []),                        # -2 cannot be: LLVM's range says so
    ({"inner_range": "", "check": SWITCH.format(more="")}, GIL_ENSURE + [("raiser", "NRT_MemInfo_alloc")]),
])
def test_helper_calls_are_found_on_the_paths_that_raise_nothing(change, found):
    """numba's helpers may lie where a call raises (the blocks that only return an error status,
    or that a failed call's status leads to), nowhere else."""
    assert flow.helper_calls(MODULE.format(**{**RAISING, **change}), "root") == found


@pytest.mark.slow                   # the engine's files, made if missing
def test_the_engines_modules_call_numbas_helpers_only_where_they_raise(engine_files):
    """The integrator's and the BVH build's modules (made by numba now, as make does) reach numba's
    helpers and Python's only on paths that raise, and do reference them there."""
    from rtcli.rendering.warmup import _scenes
    engine = choose(_scenes()[0], "compiled", notes=lambda text: None)
    lo = np.random.default_rng(0).random((64, 3))
    levels = variants.compiled(bvh_build.levels)
    for name, body, args, results in [(fast.ENTRY, fast.compiled_integrator(), engine.empty_call, 0),
                                      (compiled_build.LEVELS, levels, bvh_build.levels_args(lo, lo + 0.1, 2, 12), 2)]:
        _, module = writing._module(name, body, args, results)
        text = str(module)
        assert flow.helper_calls(text, writing.BODY_SYMBOL) == [], name
        functions, variables = llvmir.foreign_symbols(text)
        assert {"numba_gil_ensure", "numba_do_raise"} <= set(functions) and "PyExc_RuntimeError" in variables, name


def test_numba_symbols_read_as_python_names():
    assert llvmir.readable("_ZN5rtcli6shapes7polygon3hitB4v129B46c8tJTIeFI") == "rtcli.shapes.polygon.hit"
    assert llvmir.readable("NRT_decref") == "NRT_decref"


def test_the_wrapper_rebuilds_each_kind_of_argument():
    source, tuples = arguments.wrapper_source(
        [(arguments.layout(a), arguments.classes(a)) for a in small_args()], 2)
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
    from rtcli.rendering.warmup import _scenes, machine_code
    entries._loaded.clear()
    made, why = machine_code(choose(_scenes()[0], "compiled", notes=lambda text: None))
    assert made == [fast.ENTRY, compiled_build.LEVELS], why
    return made


SCENES = ["whitted", "csg", "bubble", "textures", "teapot", "inspect"]


@pytest.mark.slow                   # the engine's files, made if missing
@pytest.mark.parametrize("name", SCENES)
def test_the_integrators_file_gives_numbas_pixels(engine_files, name):
    scene = load_scene(str(ROOT / "scenes" / f"{name}.yaml"))
    engine = choose(scene, "compiled")
    assert engine.entry is not None                      # from the file
    job = Job(64, 48, engine="compiled")
    i, j = np.meshgrid(np.arange(64), np.arange(48))
    from_file, counts_file = render_tile(scene, job, i.ravel(), j.ravel(), engine)
    engine.entry = None                                  # numba's dispatcher
    from_numba, counts_numba = render_tile(scene, job, i.ravel(), j.ravel(), engine)
    assert np.array_equal(from_file, from_numba) and counts_file == counts_numba
    assert from_file.std() > 0.01                        # a picture, not a blank


@pytest.mark.slow                   # the engine's files, made if missing
def test_the_bvh_builds_file_builds_the_reference_tree(engine_files):
    from bvh_reference import build as reference_build
    lo = np.random.default_rng(5).normal(size=(3000, 3))
    hi = lo + np.random.default_rng(6).uniform(0, 0.2, size=(3000, 3))
    entry = machinecode.load(compiled_build.LEVELS)
    assert entry is not None and entry.fits(bvh_build.levels_args(lo, hi, 2, 12))
    tree = compiled_build.build(lo, hi, 2, 12, variant=entry)
    for got, want in zip(tree, reference_build(lo, hi, 2, 12)):
        assert np.array_equal(got, want)


@pytest.mark.slow                   # the engine's files, made if missing
def test_a_render_with_the_files_does_not_load_numba(engine_files, tmp_path):
    code = ("import sys, rtcli; img = rtcli.render(sys.argv[1], width=48, height=36); "
            "print(img.stats.engine, 'numba' in sys.modules)")
    for scene in ("whitted", "teapot"):
        done = subprocess.run([sys.executable, "-c", code, str(ROOT / "scenes" / f"{scene}.yaml")],
                              capture_output=True, text=True, cwd=tmp_path, timeout=120)
        assert done.returncode == 0, done.stderr
        assert done.stdout.split() == ["compiled", "False"], (scene, done.stdout, done.stderr)


@pytest.mark.slow                   # the engine's files, made if missing
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
