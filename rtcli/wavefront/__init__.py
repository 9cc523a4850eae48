"""The numpy wavefront engine: arrays of rays, traced tile by tile (notes 000 11.7).

intersect.py finds first hits, surfaces and shadow feelers, accel.py the BVH over a
scene's objects, shade.py the local term, trace.py the recursion. The formulas are
the shared kernels of rtcli/core/ and rtcli/shapes/, run on whole arrays.
"""

from __future__ import annotations

import numpy as np

from rtcli import variants
from rtcli.shapes.mesh import Mesh
from rtcli.wavefront.accel import Accelerator


def prepare(scene, bvh: bool = True) -> None:
    """Ready a scene for the numpy engine: a BVH over its objects when there are enough of them
    (unless `bvh` is False), the compiled walks it will use loaded now and each mesh's BVH
    built, so that worker processes forked later inherit them."""
    if not (bvh and scene.wants_bvh):
        scene.accel = None
    elif scene.accel is None:
        scene.accel = Accelerator(scene)
    if variants.ENABLED and uses_compiled_walks(scene):
        _warm_up(scene)
    for o in scene.objects:                 # each mesh's tree, built once here, not in every worker
        if isinstance(o.shape, Mesh):
            _ = o.shape.bvh


def uses_compiled_walks(scene) -> bool:
    """Whether tracing this scene calls the compiled walk (meshes, sets of spheres)."""
    meshes = any(o.shape.kernels is not None and o.shape.kernels.hit is None for o in scene.objects)
    return meshes or (scene.accel is not None and scene.accel.all_spheres)


def _warm_up(scene) -> None:
    from rtcli.compiled import drop_stale_cache, query  # noqa: F401 (numba: meshes build their trees compiled)
    from rtcli.wavefront.intersect import find_first_hit
    from rtcli.wavefront.rays import Rays
    drop_stale_cache()
    find_first_hit(scene, Rays(np.zeros((3, 1)), np.ones((3, 1))))
