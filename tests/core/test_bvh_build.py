"""The BVH builds (rtcli/core/bvh_build.py) make the tree of the first build (bvh_reference.py),
number for number: numpy's, the compiled one and its plain-Python variant, on boxes of
many kinds. The same tree means the same walks, so the same pixels."""

import os
import pickle
import sys

import numpy as np
import pytest
from bvh_reference import build as reference_build

from rtcli.compiled import build as compiled_build
from rtcli.core import bvh_build
from rtcli.core.bvh import BVH
from rtcli.kernels import machinecode, variants
from rtcli.scenefile.obj import read_obj
from rtcli.shapes.mesh import Mesh

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # tests/
MODELS = "/work/shared/models"
needs_numba = pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")


def face_boxes(path):
    obj = read_obj(path)
    a, b, c = (obj.vertices[obj.faces[:, j]] for j in range(3))
    return np.minimum(np.minimum(a, b), c), np.maximum(np.maximum(a, b), c)


def cases():
    """(name, lo, hi): random boxes of many counts, boxes on a grid (ties of centroids and of
    costs), identical boxes (no cut splits them), flat boxes, far-off and tiny coordinates."""
    rng = np.random.default_rng(5)
    out = []
    for m in (1, 2, 3, 4, 5, 6, 9, 17, 40, 100, 333, 1000):
        lo = rng.uniform(-1, 1, (m, 3))
        out.append((f"random{m}", lo, lo + rng.uniform(0, 0.2, (m, 3))))
    lo = rng.integers(-4, 4, (300, 3)).astype(float)
    out.append(("grid", lo, lo + rng.integers(0, 3, (300, 3))))
    out.append(("identical", np.zeros((50, 3)), np.ones((50, 3))))
    lo = rng.uniform(-1, 1, (200, 3))
    lo[:, 1] = 0.0
    out.append(("flat", lo, lo + rng.uniform(0, 0.1, (200, 3)) * [1, 0, 1]))
    out.append(("two clusters", *(np.concatenate([rng.uniform(0, 1, (64, 3)), rng.uniform(10, 11, (64, 3))]),) * 2))
    lo = rng.uniform(-1e19, 1e19, (120, 3))
    out.append(("huge", lo, lo + 1e17))
    lo = rng.uniform(-1e-18, 1e-18, (120, 3))
    out.append(("tiny", lo, lo + 1e-20))
    lo = np.repeat(rng.uniform(-1, 1, (30, 3)), 7, axis=0)               # clumps of equal centroids
    out.append(("clumps", lo, lo + 0.01))
    return out


def same_tree(a, b):
    assert len(a) == len(b) == 7
    for x, y, name in zip(a, b, ("lo", "hi", "child", "start", "count", "perm", "depth")):
        np.testing.assert_array_equal(x, y, err_msg=name)
        if name != "depth":
            assert np.asarray(x).dtype == np.asarray(y).dtype and np.shape(x) == np.shape(y), name


SIZES = [(4, 12), (2, 12), (1, 5), (3, 2), (8, 32)]          # (leaf_size, bins)


@pytest.mark.parametrize("leaf_size, bins", SIZES)
@pytest.mark.parametrize("case", cases(), ids=lambda c: c[0])
def test_numpy_build_is_the_reference_tree(case, leaf_size, bins):
    _, lo, hi = case
    same_tree(bvh_build.numpy_build(lo, hi, leaf_size, bins), reference_build(lo, hi, leaf_size, bins))


@needs_numba
@pytest.mark.parametrize("leaf_size, bins", SIZES)
@pytest.mark.parametrize("case", cases(), ids=lambda c: c[0])
def test_compiled_build_is_the_reference_tree(case, leaf_size, bins):
    _, lo, hi = case
    same_tree(compiled_build.build(lo, hi, leaf_size, bins), reference_build(lo, hi, leaf_size, bins))


@pytest.mark.parametrize("case", cases()[:14] + cases()[-3:], ids=lambda c: c[0])
def test_python_variant_of_the_compiled_build_is_the_reference_tree(case):
    _, lo, hi = case
    same_tree(compiled_build.build(lo, hi, 2, 12, variants.python(bvh_build.levels)),
              reference_build(lo, hi, 2, 12))


@pytest.mark.parametrize("model", ["stanford-bunny.obj", "spot.obj"])
def test_models_and_the_bench_torus_give_the_reference_tree(model):
    path = os.path.join(MODELS, model)
    if not os.path.exists(path):
        pytest.skip(f"{path} is not here")
    lo, hi = face_boxes(path)
    ref = reference_build(lo, hi, 4, 12)
    same_tree(bvh_build.numpy_build(lo, hi, 4, 12), ref)
    if variants.ENABLED:
        same_tree(compiled_build.build(lo, hi, 4, 12), ref)


@needs_numba
def test_torus100k_compiled_is_the_reference_tree():
    lo, hi = face_boxes(os.path.join(HERE, "..", "bench", "torus100k.obj"))
    same_tree(compiled_build.build(lo, hi, 4, 12), reference_build(lo, hi, 4, 12))


def test_the_compiled_build_is_at_hand_once_numba_is_loaded_or_its_machine_code_is(monkeypatch):
    """compiled/build.py's runner, which the engine choice hands to what builds trees, exists when
    the compiled `levels` starts at once; a tree given it builds through it."""
    monkeypatch.setattr(machinecode, "load", lambda name: None)
    monkeypatch.setattr(variants, "ENABLED", True)
    monkeypatch.setitem(sys.modules, "numba", sys.modules.get("numba", object()))
    assert compiled_build.runner() is compiled_build.run
    monkeypatch.delitem(sys.modules, "numba")
    assert compiled_build.runner() is None
    monkeypatch.setattr(machinecode, "load", lambda name: name == compiled_build.LEVELS and object())
    assert compiled_build.runner() is compiled_build.run
    monkeypatch.setattr(variants, "ENABLED", False)
    assert compiled_build.runner() is None
    calls = []
    run = variants.python(bvh_build.levels)
    lo = np.random.default_rng(1).uniform(0, 1, (50, 3))
    tree = BVH(lo, lo + 0.1, levels=lambda *args: calls.append(len(args[0])) or run(*args))
    assert calls == [50]
    np.testing.assert_array_equal(tree.perm, BVH(lo, lo + 0.1).perm)


# --- a mesh builds its tree when first asked for ---
def test_a_mesh_builds_its_tree_on_first_use_and_keeps_its_bounds():
    obj = read_obj(os.path.join(HERE, "data", "polygons.obj"))
    mesh = Mesh(obj.vertices, obj.faces)
    assert mesh._bvh is None
    lo, hi = mesh.bounds()
    copy = pickle.loads(pickle.dumps(mesh))                      # unbuilt, it still pickles
    tree = mesh.bvh
    assert mesh.bvh is tree and mesh._boxes is None
    np.testing.assert_array_equal(tree.bounds()[0], lo)
    np.testing.assert_array_equal(tree.bounds()[1], hi)
    for x, y in ((tree.nodes, copy.bvh.nodes), (tree.links, copy.bvh.links), (tree.perm, copy.bvh.perm)):
        np.testing.assert_array_equal(x, y)
    built = pickle.loads(pickle.dumps(mesh))
    assert built._bvh is not None and built._boxes is None


def test_the_numpy_engine_builds_mesh_trees_before_its_workers_fork(yaml_scene, monkeypatch):
    from rtcli import wavefront
    monkeypatch.setattr(variants, "ENABLED", False)            # the numpy walk: the tree is needed in each worker
    scene = yaml_scene(f"""
        camera: {{eye: [0, 0, 5], look_at: [0, 0, 0]}}
        objects:
          - mesh: {{file: {os.path.join(HERE, "data", "polygons.obj")}}}
        """)
    mesh = scene.objects[0].shape
    assert mesh._bvh is None
    wavefront.prepare(scene)
    assert mesh._bvh is not None
