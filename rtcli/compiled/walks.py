"""The numpy engine's BVH walks, compiled: the per-ray walk of core/bvh.py run over arrays of rays,
over a mesh's triangles or over a scene's tree of spheres. The same answers as the numpy walks,
faster; the engine choice (rendering/engine.py) gives a Walks to the numpy engine when numba is
installed (Scene.walks), and the numpy engine calls it without knowing what it is."""

from __future__ import annotations

import time
import weakref

import numpy as np

from rtcli.compiled import query
from rtcli.compiled.loading import ready
from rtcli.compiled.pack import geometry, mesh_geometry
from rtcli.core.bvh import ANY_CASTER, NEAREST

WALKS = "the numpy engine's BVH walks"


class Walks:
    """The compiled walks, each scene's packed arrays kept while the scene lives."""

    def __init__(self):
        self._meshes = weakref.WeakKeyDictionary()           # mesh shape -> packed geometry
        self._trees = weakref.WeakKeyDictionary()            # accelerator -> (packed geometry, depth)

    def mesh(self, shape, o, d, t_min, t_max, shadow: bool):
        """The walk over a mesh's tree for rays o, d (3, n): (t, face), or with `shadow` the blocked mask."""
        n = o.shape[1]
        if shape not in self._meshes:
            self._meshes[shape] = mesh_geometry(shape)
        t, face, prim = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
        lo, hi = (np.broadcast_to(np.asarray(x, float), (n,)).copy() for x in (t_min, t_max))
        query.WALK_RAYS_TRIANGLES(self._meshes[shape], 0, np.ascontiguousarray(o), np.ascontiguousarray(d), lo, hi,
                                  ANY_CASTER if shadow else NEAREST,
                                  t, face, prim, np.empty(shape.bvh.depth + 2, np.int64))
        return (face >= 0) if shadow else (t, face)

    def objects(self, accel, scene, o, d, t_min, t_max, mode: int):
        """The walk over the scene's tree (wavefront/accel.py's): (t, object, prim) per ray (mode: core/bvh.py)."""
        if accel not in self._trees:
            self._trees[accel] = geometry(scene, tree=True, bvh=(accel.members, accel.bvh))
        geo, depth = self._trees[accel]
        n = o.shape[1]
        t, obj, prim = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
        lo, hi = (np.broadcast_to(np.asarray(x, float), (n,)).copy() for x in (t_min, t_max))
        query.WALK_RAYS_OBJECTS(geo, 0, np.ascontiguousarray(o), np.ascontiguousarray(d), lo, hi, mode,
                                t, obj, prim, np.empty(depth, np.int64))
        return t, obj, prim

    def calls(self, scene, mesh, spheres: bool) -> tuple[list, list]:
        """(the walks, a call of each on one ray) that a scene readied for the numpy engine uses
        (`mesh`: one of its meshes, or None; `spheres`: its BVH holds only spheres), called as
        tracing calls them: with the same argument types, so the machine code made for them serves
        every render."""
        o, d = np.zeros((3, 1)), np.ones((3, 1))
        entries, calls = [], []
        if mesh is not None:
            entries.append(query.WALK_RAYS_TRIANGLES)
            calls.append(lambda: self.mesh(mesh, o, d, 0.0, np.inf, False))
        if spheres:
            entries.append(query.WALK_RAYS_OBJECTS)
            calls.append(lambda: self.objects(scene.accel, scene, o, d, 0.0, np.inf, NEAREST))
        return entries, calls


def warm_up(found: list[tuple[list, list]], notes=None, start: float | None = None):
    """The walks of Walks.calls (one or more scenes') loaded from numba's cache or compiled, once,
    said to `notes`: how long it took (loading.Load)."""
    start = time.perf_counter() if start is None else start
    entries = [e for scene_entries, _ in found for e in scene_entries]
    calls = [c for _, scene_calls in found for c in scene_calls]
    return ready(entries, lambda: [call() for call in calls], WALKS, "about half a minute", notes, start)
