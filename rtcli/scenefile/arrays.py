"""Big sets given as numpy arrays in a scene dict (docs/python-api.md, "Scenes from arrays").

A scene given to the Python API as a dict may hold, as an object,

    {"spheres": {"centers": C, "radii": R}, "material": ...}
    {"spheres": {"centers": C, "radii": R, "material_index": I}, "materials": [m0, m1, ...]}
    {"mesh": {"vertices": V, "faces": F, "smooth": False}, "material": ...}

with C (n, 3), R (n,) or one number, I (n,) integers into the object's `materials` list,
V (m, 3) and F (k, 3) integers counted from 0. They are checked here, whole, and kept as
arrays: a set of spheres becomes one block of n objects (core/objects.py), a mesh one
object, without a Python value per sphere, vertex or face. A wrong array is an error at
its key path, naming the first wrong entry.
"""

from __future__ import annotations

import numpy as np

from rtcli.errors import SceneError, Where, shown
from rtcli.scenefile.limits import MAX_MAGNITUDE, MAX_OBJECTS, RANGE

DICT = "<dict>"
SPHERE_KEYS = ("centers", "radii", "material_index")
MESH_KEYS = ("vertices", "faces", "smooth")


class SphereArrays:
    """n spheres: centers (n, 3), radii (n,), index (n,) into the object's `materials`, or None."""

    __slots__ = ("centers", "radii", "index")

    def __init__(self, centers, radii, index):
        self.centers, self.radii, self.index = centers, radii, index

    def __len__(self) -> int:
        return len(self.radii)


class MeshArrays:
    """A mesh's vertices (m, 3), faces (k, 3) counted from 0, and whether it is smooth."""

    __slots__ = ("vertices", "faces", "smooth")

    def __init__(self, vertices, faces, smooth: bool):
        self.vertices, self.faces, self.smooth = vertices, faces, smooth


def wants_arrays(key: str, value) -> bool:
    """Whether an object's `key: value` is a set given as arrays: `spheres`, or a `mesh` with `vertices`."""
    return isinstance(value, dict) and (key == "spheres" or (key == "mesh" and "vertices" in value))


def arrays_of(key: str, value: dict, path: str):
    """The SphereArrays or MeshArrays of an object's `spheres` or `mesh` value, checked."""
    allowed = SPHERE_KEYS if key == "spheres" else MESH_KEYS
    for name in value:
        if name not in allowed:
            raise _error(f"{path}.{shown(name)}", f"unknown key; allowed here: {', '.join(allowed)}")
    if key == "spheres":
        return _spheres(value, path)
    vertices = _numbers(value, "vertices", path, (None, 3))
    faces = _integers(value, "faces", path, (None, 3), len(vertices))
    smooth = value.get("smooth", False)
    if not isinstance(smooth, (bool, np.bool_)):
        raise _error(f"{path}.smooth", f"must be true or false, got {type(smooth).__name__}")
    return MeshArrays(vertices, faces, bool(smooth))


def _spheres(value: dict, path: str) -> SphereArrays:
    centers = _numbers(value, "centers", path, (None, 3))
    if len(centers) > MAX_OBJECTS:
        raise _error(f"{path}.centers", f"{len(centers):,} spheres: a scene holds at most {MAX_OBJECTS:,} objects")
    radii = _numbers(value, "radii", path, (len(centers),), scalar=True)
    if (bad := np.flatnonzero(radii <= 0)).size:
        raise _error(f"{path}.radii", f"radii must be > 0: radii[{bad[0]}] is {radii[bad[0]]:g}")
    index = _integers(value, "material_index", path, (len(centers),), None) if "material_index" in value else None
    return SphereArrays(centers, radii, index)


def _array(value: dict, key: str, path: str):
    if key not in value:
        raise _error(f"{path}.{key}", "missing required key")
    try:
        return np.asarray(value[key])
    except (ValueError, TypeError) as e:
        raise _error(f"{path}.{key}", f"must be an array: {e}") from None


def _numbers(value: dict, key: str, path: str, shape: tuple, scalar: bool = False) -> np.ndarray:
    """value[key] as a float64 array of `shape` (None: any length), every entry finite and within
    +-MAX_MAGNITUDE; `scalar`: one number stands for all."""
    a = _array(value, key, path)
    if a.dtype.kind not in "iuf" or a.dtype.kind == "b":
        raise _error(f"{path}.{key}", f"must be an array of numbers, got an array of {a.dtype}")
    if scalar and a.ndim == 0:
        a = np.full(shape, a, dtype=float)
    _check_shape(a, key, path, shape)
    a = np.ascontiguousarray(a, dtype=float)
    ok = np.isfinite(a) & (np.abs(a) <= MAX_MAGNITUDE)
    if not ok.all():
        at = np.unravel_index(int(np.argmin(ok)), a.shape)
        where = "][".join(str(int(i)) for i in at)
        raise _error(f"{path}.{key}", f"entries must be finite numbers {RANGE}: {key}[{where}] is {a[at]:g}")
    return a


def _integers(value: dict, key: str, path: str, shape: tuple, below: int | None) -> np.ndarray:
    """value[key] as an int64 array of `shape`, each >= 0 (and < below when given)."""
    a = _array(value, key, path)
    if a.dtype.kind not in "iu":
        raise _error(f"{path}.{key}", f"must be an array of integers, got an array of {a.dtype}")
    _check_shape(a, key, path, shape)
    a = np.ascontiguousarray(a, dtype=np.int64)
    wrong = (a < 0) if below is None else (a < 0) | (a >= below)
    if wrong.any():
        at = np.unravel_index(int(np.argmax(wrong)), a.shape)
        limit = ">= 0" if below is None else f"in 0..{below - 1} (counted from 0)"
        raise _error(f"{path}.{key}", f"entries must be {limit}: {key}[{']['.join(str(int(i)) for i in at)}] "
                                      f"is {int(a[at])}")
    return a


def _check_shape(a: np.ndarray, key: str, path: str, shape: tuple) -> None:
    want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
    if a.ndim != len(shape) or any(s is not None and s != t for s, t in zip(shape, a.shape)):
        raise _error(f"{path}.{key}", f"must be an array of shape {want}, got shape {tuple(a.shape)}")


def _error(path: str, message: str) -> SceneError:
    return SceneError(Where(DICT, 0, 0), path, message)
