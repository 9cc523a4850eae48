"""`rtcli warmup`: every compiled function the engines call, compiled now or loaded from the cache.

The compiled engine calls one entry point, the integrator (trace_camera); the numpy engine
calls two compiled walks, over a mesh's triangles and over a BVH of spheres. Each is called
here once, through the engines' own code on two small scenes made in code, so with the same
argument types as in any render: afterwards no render compiles (tests/compiled/test_startup.py renders
every scene and checks that). A second warmup loads the code from the cache in well under a
second and says that nothing was compiled.
"""

from __future__ import annotations

import compileall
import time
from functools import partial

import numpy as np

from rtcli import wavefront
from rtcli.compiled import ENTRY, compiled_integrator
from rtcli.compiled import build as compiled_build
from rtcli.compiled.loading import Load
from rtcli.core.bvh_build import levels, levels_args
from rtcli.core.camera import from_fov
from rtcli.core.lights import PointLight
from rtcli.core.materials import Material, MaterialTable
from rtcli.core.scene import Scene, SceneObject
from rtcli.errors import RtcliError
from rtcli.kernels import machinecode, numba_cache, variants
from rtcli.rendering.engine import choose
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.plane import Plane
from rtcli.shapes.sphere import Sphere


def _scenes():
    """(nine spheres over a plane: the integrator with a BVH, the walk over spheres; a mesh)."""
    camera = partial(from_fov, np.array([0.0, 2, 8]), np.zeros(3), [0, 1, 0], 40.0)
    lights = [PointLight(np.array([4.0, 6, 4]), np.ones(3), np.array([1.0, 0, 0]))]
    spheres = [SceneObject(k + 1, "", Sphere((k % 3 - 1.0, 0.5, k // 3 - 1.0), 0.4), 0) for k in range(9)]
    floor = SceneObject(10, "", Plane((0, 0, 0)), 0)
    materials = MaterialTable([Material()])
    mesh = SceneObject(1, "", Mesh.examples()[0], 0)
    return (Scene(camera, spheres + [floor], materials, lights, eye=np.array([0.0, 2, 8])),
            Scene(camera, [mesh, floor], materials, lights, eye=np.array([0.0, 2, 8])))


def warmup(notes=None) -> tuple[list[tuple[str, Load]], tuple[list[str], str | None]]:
    """Load or compile the machine code of every compiled entry point: (what, how long) for the
    render engine and the numpy engine's walks, and the entries with a machine code file and why
    one is missing (machine_code). `notes` hears when one compiles (default: stderr). RtcliError when numba
    cannot be loaded."""
    if not variants.ENABLED:
        raise RtcliError("numba is not installed: nothing to compile (the numpy engine needs none; "
                         "pip install -e '.[fast]' in the rtcli folder for the compiled engine)")
    from rtcli.compiled.walks import WALKS, Walks, warm_up  # start-up: numba
    spheres, mesh = _scenes()
    engine = choose(spheres, "compiled", notes=notes)
    start, found = time.perf_counter(), []
    for scene in (spheres, mesh):
        wavefront.build(scene)
        found.append(Walks().calls(scene, *wavefront.walked(scene)))
    walks = warm_up(found, notes, start)
    return [("the render engine (compiled)", engine.load), (WALKS, walks)], machine_code(engine)


def machine_code(engine) -> tuple[list[str], str | None]:
    """Write the machine code files (rtcli/kernels/machinecode) of the integrator and of the BVH build,
    unless they are at hand and fit (`engine`: a Compiled, whose arguments the file takes): the
    entries that have a usable file afterwards, and why one could not be written (or None)."""
    why, found = None, machinecode.load(ENTRY)
    if found is None or not found.fits(engine.empty_call):
        why = machinecode.make(ENTRY, compiled_integrator(), engine.empty_call)
    if machinecode.load(LEVELS) is None:
        lo = np.random.default_rng(0).random((64, 3))
        args = levels_args(lo, lo + 0.1, 2, 12)
        run = variants.compiled(levels)
        run(*args)
        why = machinecode.make(LEVELS, run, args, results=2) or why
    return [name for name in (ENTRY, LEVELS) if machinecode.load(name) is not None], why


LEVELS = compiled_build.LEVELS


def bytecode() -> bool:
    """Compile rtcli's Python files to bytecode where Python keeps it (each folder's __pycache__),
    so that no run compiles them again (a run that may not write bytecode, PYTHONDONTWRITEBYTECODE,
    would every time); whether that worked."""
    return bool(compileall.compile_dir(numba_cache.PACKAGE_DIR, quiet=2))
