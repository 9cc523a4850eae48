"""The numpy wavefront engine: arrays of rays, traced tile by tile (notes 000 11.7).

intersect.py finds first hits, surfaces and shadow feelers, accel.py the BVH over a
scene's objects, shade.py the local term, trace.py the recursion. The formulas are
the shared kernels of rtcli/core/ and rtcli/shapes/, run on whole arrays.
"""

from __future__ import annotations

from rtcli.core.objects import singles
from rtcli.shapes.mesh import Mesh
from rtcli.wavefront.accel import Accelerator


def prepare(scene, bvh: bool = True, walks=None, levels=None) -> None:
    """Ready a scene for the numpy engine: a BVH over its objects when there are enough of them
    (unless `bvh` is False) and each mesh's BVH built now, so that worker processes forked later
    inherit them. `walks`: compiled BVH walks to trace meshes and sets of spheres with (Scene.walks,
    None for numpy's); `levels`: the compiled tree build (core/bvh_build.py). The engine choice
    (rendering/engine.py) says which; this engine imports neither."""
    scene.walks = walks
    build(scene, bvh, levels)
    for _, o in singles(scene.objects):     # each mesh's tree, built once here, not in every worker
        if isinstance(o.shape, Mesh):
            o.shape.tree(levels)


def build(scene, bvh: bool = True, levels=None) -> None:
    """The BVH over the scene's objects when there are enough of them (unless `bvh` is False)."""
    if not (bvh and scene.wants_bvh):
        scene.accel = None
    elif scene.accel is None:
        scene.accel = Accelerator(scene, levels)


def walked(scene) -> tuple:
    """(a mesh of the scene or None, whether the scene's BVH holds only spheres): what tracing it
    would hand to compiled walks, if it had them (Scene.walks)."""
    mesh = next((o.shape for _, o in singles(scene.objects) if isinstance(o.shape, Mesh)), None)
    return mesh, scene.accel is not None and scene.accel.all_spheres
