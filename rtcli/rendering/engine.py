"""The one place that picks the engine (docs/architecture.md, Engines): the numpy engine
(rtcli/wavefront/) or the compiled one (rtcli/compiled/), from the scene, the size of the job and
what is compiled; and each readied for the job. The engines import nothing of each other: the
numpy engine is handed the compiled BVH walks and tree build from here, when numba is installed.

`auto` takes the compiled engine when numba is installed and the scene holds only what it
supports (compiled.unsupported), for jobs of AUTO_RAYS primary rays and more (a 1280x800 image,
or 640x480 with --samples 2); and for any size when it starts at once (its machine code file,
without numba), or when the numpy engine would load compiled walks anyway (meshes, sets of
spheres) and the integrator's code is cached: then it starts as fast and traces faster. Smaller
jobs stay on numpy, which needs no numba start-up.
"""

from __future__ import annotations

import time

from rtcli import compiled, wavefront
from rtcli.kernels import variants
from rtcli.compiled import build as compiled_build
from rtcli.errors import RtcliError

AUTO_RAYS = 1_000_000


def prepare(scene, job, traced: int, notes=None):
    """(engine, load): the compiled engine for the job (a compiled.Compiled), or None with the scene
    readied for the numpy engine; and how long loading compiled code took (loading.Load, None when
    nothing was loaded). `traced`: the job's primary rays; `notes` is told when code compiles."""
    engine = None if job.signature else choose(scene, job.engine, _weighed(scene, job, traced), job.bvh, notes)
    if engine:
        return engine, engine.load
    return None, numpy_engine(scene, job.bvh, notes)


def choose(scene, engine: str, rays: int = AUTO_RAYS, bvh: bool = True, notes=None):
    """The compiled engine for `scene`, or None for the numpy engine; RtcliError when `engine` is
    "compiled" and it cannot be had. `rays`: how many primary rays the job traces; `bvh`: a BVH over
    the scene's objects when there are enough of them. Its `load` says how long it took to start."""
    if engine == "numpy" or (engine == "auto" and rays < AUTO_RAYS):
        return None
    start = time.perf_counter()
    shape = compiled.unsupported(scene)
    why = f"it does not handle {shape} (--engine numpy does)" if shape else compiled.why_not()
    if why is None:
        try:
            return compiled.Compiled(scene, bvh, notes, start)
        except RtcliError as e:                 # numba was needed after all, and cannot be loaded
            why = str(e)
    if engine == "compiled":
        raise RtcliError(f"--engine compiled cannot render this scene: {why}")
    return None


def numpy_engine(scene, bvh: bool = True, notes=None):
    """Ready the scene for the numpy engine, with the compiled BVH walks and tree build when numba
    is installed (the same answers, faster): how long loading the walks took (loading.Load, None
    when the scene needs none). `notes` is told when they compile."""
    wavefront.build(scene, bvh, compiled_build.runner())
    mesh, spheres = wavefront.walked(scene)
    walks = load = None
    if variants.ENABLED and (mesh is not None or spheres):
        from rtcli.compiled.walks import Walks, warm_up  # start-up: numba, only for the scenes that want it
        walks = Walks()
        load = warm_up([walks.calls(scene, mesh, spheres)], notes)
    wavefront.prepare(scene, bvh, walks, compiled_build.runner())      # numba may be loaded now
    return load


def _weighed(scene, job, traced: int) -> int:
    """The rays `auto` weighs: a small job counts as a large one when the compiled engine would start
    as fast as the numpy one (module docstring). (Not cached, the integrator would compile for a
    minute; the walks compile in seconds.)"""
    if job.engine != "auto" or traced >= AUTO_RAYS or not variants.ENABLED:
        return traced
    if compiled.starts_at_once():
        return AUTO_RAYS
    wavefront.build(scene, job.bvh)
    mesh, spheres = wavefront.walked(scene)
    if (mesh is not None or spheres) and compiled.ready_to_load():
        return AUTO_RAYS
    return traced
