"""The numpy wavefront engine: arrays of rays, traced tile by tile (notes 000 11.7).

intersect.py finds first hits, surfaces and shadow feelers, accel.py the BVH over a
scene's objects, shade.py the local term, trace.py the recursion. The formulas are
the shared kernels of rtcli/core/ and rtcli/shapes/, run on whole arrays.
"""

from __future__ import annotations

import time

import numpy as np

from rtcli import variants
from rtcli.shapes.mesh import Mesh
from rtcli.wavefront.accel import Accelerator


def prepare(scene, bvh: bool = True, notes=None):
    """Ready a scene for the numpy engine: a BVH over its objects when there are enough of them
    (unless `bvh` is False), the compiled walks it will use loaded now and each mesh's BVH
    built, so that worker processes forked later inherit them. Returns how long loading the
    walks took (compiled.Load, or None when the scene needs none); `notes`: where to say that
    they are being compiled."""
    build(scene, bvh)
    load = _warm_up(scene, notes) if variants.ENABLED and uses_compiled_walks(scene) else None
    for o in scene.objects:                 # each mesh's tree, built once here, not in every worker
        if isinstance(o.shape, Mesh):
            _ = o.shape.bvh
    return load


def build(scene, bvh: bool = True) -> None:
    """The BVH over the scene's objects when there are enough of them (unless `bvh` is False)."""
    if not (bvh and scene.wants_bvh):
        scene.accel = None
    elif scene.accel is None:
        scene.accel = Accelerator(scene)


def _walks_meshes(scene):
    """A mesh of the scene (hit through the compiled walk over its triangles), or None."""
    return next((o.shape for o in scene.objects if o.shape.kernels is not None and o.shape.kernels.hit is None),
                None)


def uses_compiled_walks(scene) -> bool:
    """Whether tracing this scene calls the compiled walk (meshes, sets of spheres)."""
    return _walks_meshes(scene) is not None or (scene.accel is not None and scene.accel.all_spheres)


def _warm_up(scene, notes=None):
    """Each compiled walk the scene uses called once, on one ray, as tracing calls it."""
    start = time.perf_counter()
    from rtcli.compiled.loading import ready
    entries, call = walks(scene)
    return ready(entries, call, WALKS, "about half a minute", notes, start)


WALKS = "the numpy engine's BVH walks"


def walks(scene) -> tuple[list, object]:
    """The compiled walks the scene uses, and a call of each on one ray, made as tracing makes it
    (the same argument types: the machine code made for it serves every render)."""
    from rtcli.compiled import drop_stale_cache
    drop_stale_cache()
    from rtcli.compiled import query
    from rtcli.core.bvh import NEAREST
    from rtcli.wavefront.intersect import compiled_walk
    o, d = np.zeros((3, 1)), np.ones((3, 1))
    mesh, entries, calls = _walks_meshes(scene), [], []
    if mesh is not None:
        entries.append(query.WALK_RAYS_TRIANGLES)
        calls.append(lambda: compiled_walk(mesh, o, d, 0.0, np.inf, False))
    if scene.accel is not None and scene.accel.all_spheres:
        entries.append(query.WALK_RAYS_OBJECTS)
        calls.append(lambda: scene.accel.compiled_walk(scene, o, d, 0.0, np.inf, NEAREST))
    return entries, lambda: [call() for call in calls]
