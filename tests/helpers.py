"""Plain helpers for the tests (conftest.py holds the fixtures): scenes from YAML text, one-pixel renders.

Tests import them as `from helpers import ...` (pytest puts tests/ on the path).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

from rtcli.kernels import numba_cache
from rtcli.rendering.tiles import Job, render_tile
from rtcli.scenefile import yamlfile
from rtcli.scenefile.load import scene_from_docs

# exact-value tests of shading: a tolerance, two light directions, a material that shows only its
# specular or mirror term, and numbers written into YAML to the last digit
RTOL = 1e-9
E1, E2 = np.array([0.2, 0.4, 0.6]), np.array([0.9, 0.1, 0.3])
DARK = "ambient: 0, diffuse: 0"


def f(x: float) -> str:
    """x in YAML, every digit kept."""
    return format(float(x), ".17f")


def vec(v) -> str:
    """A vector in YAML, every digit kept."""
    return "[" + ", ".join(f(x) for x in v) + "]"


def scene_from_yaml(text: str, tmp_path=None, name: str = "scene.yaml"):
    """Build a Scene from YAML text; written to tmp_path when given (for includes and files)."""
    text = textwrap.dedent(text)
    if tmp_path is not None:
        path = tmp_path / name
        path.write_text(text)
        return scene_from_docs(yamlfile.load(str(path)))
    return scene_from_docs([yamlfile.parse(text, name)])


def one_pixel(scene, i: int = 0, j: int = 0, width=None, height=None) -> np.ndarray:
    """The float color of pixel (i, j), unclamped."""
    job = Job(width or scene.settings.width, height or scene.settings.height)
    color, _ = render_tile(scene, job, np.array([i]), np.array([j]))
    return color[0]


# --- numpy's two code paths: with and without AVX-512 (where it takes some math from SVML) ---
def avx512_features() -> list[str]:
    """numpy's AVX-512 code paths this CPU takes, as NPY_DISABLE_CPU_FEATURES names them."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:
        from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    return [f for f in __cpu_dispatch__ if ("512" in f or f == "X86_V4") and __cpu_features__.get(f)]


def without_avx512(args: list[str], **kwargs) -> subprocess.CompletedProcess:
    """Run `python ARGS` in a process whose numpy does not take its AVX-512 paths, with tests/ on
    its path (on a CPU without AVX-512, numpy's only path)."""
    env = dict(os.environ, NPY_DISABLE_CPU_FEATURES=" ".join(avx512_features()),
               PYTHONPATH=os.pathsep.join([os.path.dirname(__file__), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, *args], env=env, capture_output=True, text=True, timeout=600, **kwargs)
    assert done.returncode == 0, done.stderr
    return done


# a render that takes long enough to be interrupted: about 50 s on two cores with --engine numpy
SLOW = """\
image: {width: 320, height: 240}
camera: {eye: [0, 2, 8], look_at: [0, 0, 0], fov: 50}
render: {samples: 8, max_depth: 6}
lights: [{position: [5, 8, 5], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 4}}]
objects:
  - {plane: {}, material: {reflection: 0.5}}
  - {sphere: {center: [-1.5, 1, 0]}, material: {reflection: 0.8}}
  - {sphere: {center: [1.5, 1, 0]}, material: {transmission: 0.9, ior: 1.5}}
  - {torus: {major: 1, minor: 0.3}, transform: [{translate: [0, 1, -2]}]}
"""                                      # about 50 s on two cores with --engine numpy

# numba's cache index files of two entry points, by the names numba gives them
TRACE_CAMERA = "tracing.trace_camera-*.nbi"
WALKS = "bvh.walk_rays_*.nbi"


def seeded(root: Path, *without: str) -> Path:
    """A cache folder laid out as numba lays out NUMBA_CACHE_DIR (a folder per source folder),
    holding the warm cache's files but the index files matching `without` (those functions
    compile there, loading the functions they call)."""
    for d in numba_cache.COMPILED_DIRS:
        source = Path(numba_cache.PACKAGE_DIR, d)
        target = root / numba_cache.numba_subfolder(str(source))
        target.mkdir(parents=True, exist_ok=True)
        for f in (source / "__pycache__").glob("*"):
            if f.suffix in (".nbi", ".nbc", ".sha256"):
                shutil.copy2(f, target)
    for pattern in without:
        found = list(root.glob(f"*/{pattern}"))
        assert found, pattern
        for f in found:
            f.unlink()
    return root

def image_summary(path, ignore=()) -> tuple:
    """An image file's decoded pixels (mode, size, bytes) and its provenance without the render's
    time and the keys in `ignore`: what two renders of one scene with the same settings agree on.
    Their files differ by the time rtcli writes into them, so tests compare these, not bytes."""
    from PIL import Image

    from rtcli.rendering.reading import picture_meta
    with Image.open(path) as img:
        img.load()
        meta = picture_meta(img)
        frames = []
        for k in range(getattr(img, "n_frames", 1)):             # every frame of a movie
            img.seek(k)
            frames.append(img.convert("RGB").tobytes() if k else img.tobytes())
        summary = (img.mode, img.size, frames)
    assert meta, f"{path}: no provenance"
    dropped = {"rtcli.render_seconds", *(f"rtcli.{k}" for k in ignore)}
    return summary, {k: v for k, v in meta.items() if k not in dropped}


def same_image(a, b, ignore=()) -> bool:
    """Whether two image files hold the same pixels and provenance (image_summary)."""
    return image_summary(a, ignore) == image_summary(b, ignore)


# Two glass balls inside a third: most rays stay inside, and each surface sends two on (the deep
# ray trees of render: adc_bailout and explain's node budget).
DEEP = """
image: {width: 40, height: 30}
camera: {eye: [0, 0, 4.5], look_at: [0, 0, 0], fov: 50}
background: [0.3, 0.5, 0.8]
render: {max_depth: DEPTH, adc_bailout: BAILOUT}
lights: [{position: [2, 2.5, 3]}]
materials:
  glass: {diffuse: 0.1, reflection: REFLECTION, transmission: TRANSMISSION, ior: 1.5, fresnel: FRESNEL}
objects:
  - {sphere: {center: [-1, 0, 0], radius: 0.9}, material: glass}
  - {sphere: {center: [1, 0, 0], radius: 0.9}, material: glass}
  - {sphere: {center: [0, 0, 0], radius: 6}, material: glass}
"""


def deep(depth=20, bailout="1.0e-6", reflection="1", transmission="1", fresnel="true") -> str:
    return (DEEP.replace("DEPTH", str(depth)).replace("BAILOUT", bailout).replace("REFLECTION", reflection)
            .replace("TRANSMISSION", transmission).replace("FRESNEL", fresnel))


# a small lit scene the cluster tests render on several processes and compare with a local render
CLUSTER_SCENE = """\
image: {width: 24, height: 16}
camera: {eye: [0, 1, 5], look_at: [0, 0.5, 0]}
lights: [{position: [3, 5, 4]}]
objects:
  - {plane: {}, material: {diffuse: [0.6, 0.6, 0.6], reflection: 0.2}}
  - {sphere: {center: [0, 0.5, 0], radius: 0.5}, material: {diffuse: [0.8, 0.3, 0.2], specular: 0.5}}
"""
