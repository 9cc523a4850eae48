"""The compiled code's start-up: where numba's cache lives, `rtcli warmup`, the note when rtcli
compiles, and --stats keeping start-up apart from tracing.

A whole compile of the integrator takes about half a minute, so the tests that need one compile only
a part: the warm cache beside the sources (made by `rtcli warmup`, which `make test` runs first,
or by the fixture below) is copied into a folder of its own without the index files of the
functions meant to compile; numba then compiles those alone, loading what they call.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import TRACE_CAMERA, WALKS, seeded

from rtcli import compiled as fast
from rtcli.compiled import loading
from rtcli.kernels import numba_cache, variants
from rtcli.kernels.machinecode import entries, places
from rtcli.rendering.engine import choose

pytestmark = [pytest.mark.slow,   # processes of their own, and numba caches seeded to compile in
              pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")]

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def warm():
    """The cache beside the sources, warm (a minute the first time if it is not)."""
    if numba_cache.cache_location().root is not None:
        pytest.skip("the cache is not beside the sources here (RTCLI_CACHE_DIR or NUMBA_CACHE_DIR is set)")
    from rtcli.rendering.warmup import warmup
    warmup(notes=lambda text: None)


def rtcli(*args, env=None, cwd=ROOT):
    """`python -m rtcli ARGS` in a process of its own: (exit code, stdout, stderr). In a cache of
    its own (env) it writes no machine code files (tests/kernels/test_machinecode.py has those): the
    tests here are about numba's cache, and each file takes seconds to write."""
    environment = {k: v for k, v in os.environ.items() if k not in (numba_cache.CACHE_ENV, "NUMBA_CACHE_DIR")}
    if env:
        environment["RTCLI_MACHINE_CODE"] = "0"
    environment.update(env or {})
    done = subprocess.run([sys.executable, "-m", "rtcli", *args], capture_output=True, text=True, cwd=cwd,
                          env=environment, timeout=900)
    return done.returncode, done.stdout, done.stderr




def test_warmup_says_where_the_cache_is_and_then_that_it_is_warm(warm):
    code, out, err = rtcli("warmup")
    assert code == 0, err
    assert f"cache: {os.path.join(numba_cache.PACKAGE_DIR, '*', '__pycache__')} (beside the sources)" in out
    assert "the render engine (compiled): loaded from the cache" in out
    assert "the numpy engine's BVH walks: loaded from the cache" in out
    assert "warm: nothing to compile" in out and "compiling" not in err


def test_the_compile_note_appears_exactly_when_compiling(warm, tmp_path):
    cache = seeded(tmp_path / "cache", WALKS)
    env = {numba_cache.CACHE_ENV: str(cache)}
    code, out, err = rtcli("warmup", env=env)
    assert code == 0, err
    assert f"cache: {cache} ({numba_cache.CACHE_ENV})" in out
    lines = err.splitlines()
    assert lines[0] == f"note: compiling the numpy engine's BVH walks, once (about half a minute); cached in {cache}"
    assert lines[-1].startswith("note: compiled in ")
    assert all(re.fullmatch(r"note: compiling the numpy engine's BVH walks: \d+ of \d+ functions, \d+ s", line)
               for line in lines[1:-1])                           # every few seconds, how far it has got
    assert "the render engine (compiled): loaded from the cache" in out
    assert "the numpy engine's BVH walks: compiled in" in out and out.rstrip().endswith("in all")
    assert list(cache.glob(f"*/{WALKS}"))                        # cached where it said
    code, out, err = rtcli("warmup", env=env)
    assert (code, err) == (0, "") and "warm: nothing to compile" in out


def test_a_render_that_compiles_says_so_and_keeps_it_out_of_the_render_time(warm, tmp_path):
    cache = seeded(tmp_path / "cache", TRACE_CAMERA)
    env = {numba_cache.CACHE_ENV: str(cache)}
    args = ("render", str(ROOT / "scenes" / "whitted.yaml"), "-o", str(tmp_path / "a.png"), "--width", "64",
            "--engine", "compiled", "--workers", "1", "--stats", "--json")
    code, out, err = rtcli(*args, env=env)
    assert code == 0, err
    assert err.splitlines()[0] == f"note: compiling the render engine, once (about half a minute); cached in {cache}"
    stats = json.loads(out)
    assert stats["compile_seconds"] > 0 and stats["load_seconds"] >= stats["compile_seconds"]
    assert stats["wall_seconds"] >= stats["seconds"] + stats["load_seconds"]
    assert stats["rays_per_second"] == pytest.approx(stats["total"] / stats["seconds"], rel=1e-3)
    code, out, err = rtcli(*args, env=env)
    assert (code, err) == (0, "")
    stats = json.loads(out)
    assert stats["compile_seconds"] == 0 and stats["load_seconds"] > 0
    code, out, err = rtcli(*args[:-1], env=env)
    assert code == 0 and "s more to load the compiled code" in out


def test_the_stats_line_puts_compiling_apart():
    from rtcli.api.results import RenderStats
    stats = RenderStats(8, 8, 1, "compiled", 64, 10, 0, 0, 0.5, 41.0, 40.2)
    assert stats.line().endswith(", 74 total; compiled engine; 0.50 s; 148 rays/s; 41.00 s more to compile "
                                 "the engine (once: it is cached)")
    assert stats.line(42.0).split("; ")[2] == "1.00 s"            # a wall time: start-up taken out
    assert stats.as_dict()["compile_seconds"] == 40.2 and stats.as_dict()["load_seconds"] == 41.0
    assert "more" not in RenderStats(8, 8, 1, "numpy", 64, 0, 0, 0, 0.5).line()


def test_a_read_only_install_caches_per_user(tmp_path, monkeypatch):
    """Simulated: the sources' folders are not writable (as root, chmod would not stop a write)."""
    real = numba_cache.writable
    monkeypatch.setattr(numba_cache, "writable", lambda f: not f.startswith(numba_cache.PACKAGE_DIR) and real(f))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    for name in (numba_cache.CACHE_ENV, "NUMBA_CACHE_DIR"):
        monkeypatch.delenv(name, raising=False)
    numba_cache.cache_location.cache_clear()
    try:
        where = numba_cache.cache_location()
        if sys.platform.startswith("linux"):
            assert where.root == str(tmp_path / "home-cache" / "rtcli" / "numba")
        assert where.enabled and "read-only" in where.why and str(where) == where.root
        assert where.folders()[0] == os.path.join(where.root, numba_cache.numba_subfolder(os.path.join(numba_cache.PACKAGE_DIR, "kernels")))
        monkeypatch.setenv("XDG_CACHE_HOME", "/proc/no-such-folder")          # nowhere writable: no cache
        numba_cache.cache_location.cache_clear()
        assert not numba_cache.cache_location().enabled
    finally:
        numba_cache.cache_location.cache_clear()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="XDG_CACHE_HOME places the per-user cache on Linux")
def test_numba_writes_to_the_per_user_cache_when_the_sources_are_read_only(warm, tmp_path):
    """In a process of its own, numba itself: the sources' folders refused as rtcli's check sees them."""
    user = tmp_path / "user-cache"
    cache = seeded(user / "rtcli" / "numba", TRACE_CAMERA)
    code = textwrap.dedent("""
        from rtcli.kernels import numba_cache, variants
        from rtcli.kernels import machinecode
        real = numba_cache.writable
        numba_cache.writable = lambda f: not f.startswith(numba_cache.PACKAGE_DIR) and real(f)
        from rtcli.cli import main
        main(["warmup"])
    """)
    env = {k: v for k, v in os.environ.items() if k not in (numba_cache.CACHE_ENV, "NUMBA_CACHE_DIR")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=900,
                          env={**env, "XDG_CACHE_HOME": str(user), "HOME": str(tmp_path), "RTCLI_MACHINE_CODE": "0"})
    assert done.returncode == 0, done.stderr
    assert f"cache: {cache} (the per-user cache: rtcli's folder is read-only)" in done.stdout
    assert done.stderr.startswith(f"note: compiling the render engine, once (about half a minute); cached in {cache}")
    assert list(cache.glob(f"*/{TRACE_CAMERA}"))


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a user that chmod can stop")
def test_a_read_only_copy_of_rtcli_uses_the_per_user_cache(tmp_path):
    copy = tmp_path / "site" / "rtcli"
    shutil.copytree(Path(numba_cache.PACKAGE_DIR), copy, ignore=shutil.ignore_patterns("__pycache__"))
    for folder in [copy, *(p for p in copy.rglob("*") if p.is_dir())]:
        folder.chmod(0o555)
    try:
        code = "from rtcli.kernels import numba_cache as v; w = v.cache_location(); print(v.PACKAGE_DIR, w.root, w.why)"
        env = {**os.environ, "PYTHONPATH": str(copy.parent), "XDG_CACHE_HOME": str(tmp_path / "c")}
        env.pop(numba_cache.CACHE_ENV, None), env.pop("NUMBA_CACHE_DIR", None)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                             cwd=tmp_path, check=True).stdout.split(" ", 2)
        assert out[:2] == [str(copy), str(tmp_path / "c" / "rtcli" / "numba")] and "read-only" in out[2]
    finally:
        for folder in [copy, *(p for p in copy.rglob("*") if p.is_dir())]:
            folder.chmod(0o755)


def test_numba_places_a_cache_root_as_rtcli_expects(tmp_path):
    """The stale-cache guard finds numba's files by these names; numba must agree."""
    from numba.core.caching import _CacheLocator
    from numba.misc.appdirs import AppDirs
    for d in numba_cache.COMPILED_DIRS:
        source = os.path.join(numba_cache.PACKAGE_DIR, d, "x.py")
        assert numba_cache.numba_subfolder(os.path.dirname(source)) == _CacheLocator.get_suitable_cache_subpath(source)
    assert fast._numba_user_cache() == AppDirs(appname="numba", appauthor=False).user_cache_dir


def test_the_stale_cache_guard_covers_every_place_the_cache_may_live(tmp_path, monkeypatch):
    """Beside the sources, RTCLI_CACHE_DIR, NUMBA_CACHE_DIR, the per-user cache and numba's own: a
    change in any source drops every cached file, a second look with the same sources keeps them."""
    package = tmp_path / "rtcli"
    for folder in ("kernels", "core", "shapes", "compiled"):
        (package / folder).mkdir(parents=True)
        (package / folder / "a.py").write_text(f"# {folder}\n")
    monkeypatch.setattr(fast, "PACKAGE", package)
    monkeypatch.setenv(numba_cache.CACHE_ENV, str(tmp_path / "mine"))
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numbas"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "user"))
    monkeypatch.setenv("LOCALAPPDATA", str(tmp_path / "user"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    places = fast.cache_places()
    assert len(places) == 5
    beside = {str(f) for f in places[0][0]}
    assert beside == {str(package / d / "__pycache__") for d in ("compiled", "core", "shapes", "kernels")}
    files = [folder / "a.f-1.py311.nbi" for folders, _ in places for folder in folders]
    for f in files:
        f.parent.mkdir(parents=True, exist_ok=True)

    def look(text):
        for f in files:
            f.write_text(text)
        fast.drop_stale_cache()
        return [f.exists() for f in files]
    assert look("old") == [False] * len(files)
    assert look("new") == [True] * len(files)              # same sources: the cache stays
    (package / "shapes" / "a.py").write_text("# a changed kernel\n")
    assert look("newer") == [False] * len(files)


def test_a_forecast_of_numbas_cache(tmp_path, monkeypatch):
    """loading.cached reads numba's index: False before the first compile, True after, for a new
    process (a new dispatcher of the same function); the note comes only with a compile."""
    (tmp_path / "twice_mod.py").write_text(textwrap.dedent("""
        from numba import njit

        @njit(cache=True)
        def twice(x):
            return 2 * x
    """))
    monkeypatch.syspath_prepend(str(tmp_path))
    import importlib
    heard = []

    def fresh():
        sys.modules.pop("twice_mod", None)
        return importlib.import_module("twice_mod").twice
    f = fresh()
    assert loading.cached(f) is False
    load = loading.ready([f], lambda: f(1.0), "twice", "a moment", heard.append)
    assert load.compile_seconds > 0 and heard[0].startswith("compiling twice, once (a moment); cached in ")
    assert heard[1].startswith("compiled in ") and len(heard) == 2
    g = fresh()
    assert loading.cached(g) is True
    load = loading.ready([g], lambda: g(1.0), "twice", "a moment", heard.append)
    assert load.compile_seconds == 0 and len(heard) == 2
    assert loading.ready([g], lambda: g(2.0), "twice", "a moment", heard.append).compile_seconds == 0
    assert len(heard) == 2                                            # in memory already: not even looked up


def test_a_long_compile_says_how_far_it_has_got(tmp_path, monkeypatch):
    """While numba compiles, a line every `period` seconds: how many of the functions the entries are
    made of are compiled, and for how long it has been compiling."""
    (tmp_path / "thrice_mod.py").write_text(textwrap.dedent("""
        from numba import njit

        @njit(cache=True)
        def one(x):
            return x + 1.0

        @njit(cache=True)
        def thrice(x):
            return 3 * one(x)
    """))
    monkeypatch.syspath_prepend(str(tmp_path))
    import thrice_mod
    assert set(loading.functions([thrice_mod.thrice])) == {id(thrice_mod.thrice), id(thrice_mod.one)}
    heard = []

    def slowly():
        thrice_mod.thrice(1.0)
        time.sleep(0.5)
    load = loading.ready([thrice_mod.thrice], slowly, "thrice", "a moment", heard.append, period=0.1)
    assert load.compile_seconds > 0.5 and heard[0].startswith("compiling thrice, once (a moment)")
    assert heard[-1].startswith("compiled in ") and len(heard) >= 5
    assert all(re.fullmatch(r"compiling thrice: \d of 2 functions, \d+ s", line) for line in heard[1:-1])
    assert re.fullmatch(r"compiling thrice: 2 of 2 functions, \d+ s", heard[-2])     # during the sleep: all done


def test_after_warmup_no_scene_compiles_anything(warm, monkeypatch):
    """The warmup's calls have the argument types of every render: every scene's arguments fit
    the integrator's machine code file, and through numba there is one machine code each."""
    from rtcli.compiled import query
    from rtcli.compiled.tracing import trace_camera
    from rtcli.rendering.tiles import Job, render
    from rtcli.scenefile.load import load_scene
    scenes = [load_scene(str(p)) for p in sorted((ROOT / "scenes").glob("*.yaml")) +
              sorted((ROOT / "bench").glob("*.yaml"))]
    for scene in scenes:
        assert choose(scene, "compiled").entry is not None
    monkeypatch.setattr(places, "ENABLED", False)
    monkeypatch.setattr(entries, "_loaded", {})
    for scene in scenes:
        for engine in ("numpy", "compiled") if fast.unsupported(scene) is None else ("numpy",):
            render(scene, Job(16, 12, engine=engine))
    for entry in (variants.compiled(trace_camera), query.WALK_RAYS_TRIANGLES, query.WALK_RAYS_OBJECTS):
        assert len(entry.signatures) == 1, entry.signatures


def test_warmup_without_numba_is_one_line(monkeypatch):
    from click.testing import CliRunner

    from rtcli.cli import main
    monkeypatch.setattr(variants, "ENABLED", False)
    result = CliRunner().invoke(main, ["warmup"])
    assert result.exit_code == 2 and result.output.startswith("error: numba is not installed")
    assert len(result.output.splitlines()) == 1 and "Traceback" not in result.output


def test_the_notes_of_the_api_go_where_it_is_told(warm, tmp_path):
    """rtcli.render(notes=...) hears nothing when nothing compiles; its stats hold the load time."""
    import rtcli
    heard = []
    image = rtcli.render(ROOT / "scenes" / "whitted.yaml", width=32, engine="compiled", workers=1, notes=heard.append)
    assert heard == [] and image.stats.compile_seconds == 0
    assert np.asarray(image).shape == (24, 32, 3)
