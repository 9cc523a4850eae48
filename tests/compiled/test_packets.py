"""Packets (rtcli/compiled/packets.py) against the one-ray query they stand for (query.scene_hit):
the same (t, object, prim) for every ray, bit for bit, ties included, in each of the walk's modes,
for coherent rays (a camera's, where lanes stay together) and scattered ones (where they leave)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rtcli.core.bvh import ANY_CASTER, NEAREST, NEAREST_CASTER
from rtcli.core.camera import primary_ray
from rtcli.kernels import variants
from rtcli.scenefile.load import load_scene

pytestmark = pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")

ROOT = Path(__file__).resolve().parents[2]
SCENES = ["bench/torus100k.yaml", "bench/spheres1k.yaml", "bench/quadrics.yaml", "scenes/csg.yaml",
          "scenes/suzanne.yaml", "scenes/whitted.yaml", "scenes/aquarium.yaml"]

# Exact ties: each sphere twice, and two copies of one triangle, shadowless objects beside casting ones.
TIES = """
camera: {eye: [0, 0, -6], look_at: [0, 0, 0], fov: 50}
lights: [{position: [4, 6, -6]}]
objects:
""" + "".join(f"""
  - sphere: {{center: [{x}, {y}, 0], radius: 0.4}}
  - sphere: {{center: [{x}, {y}, 0], radius: 0.4}}
    material: {{shadow: false}}""" for x in (-1.5, -0.5, 0.5, 1.5) for y in (-1, 0, 1)) + """
  - mesh: {file: twice.obj}
    transform: [{rotate: {axis: [0, 1, 0], degrees: 10}}]
"""
TWICE = "v -3 -2 1\nv 3 -2 1\nv 0 3 1\nf 1 2 3\nf 1 2 3\n"


def ties_scene(folder: Path):
    (folder / "twice.obj").write_text(TWICE)
    (folder / "ties.yaml").write_text(TIES)
    return load_scene(str(folder / "ties.yaml"))


def compiled_entries():
    from rtcli.compiled import packets, query  # numba: only where it is installed
    return variants.compiled(packets.packet_rays), variants.compiled(query.scene_rays)


def camera_rays(scene, width=64, height=48):
    cam = scene.camera(width, height)
    ys, xs = np.mgrid[0:height, 0:width] + 0.5
    r = primary_ray(cam.row, xs.ravel(), ys.ravel(), width, height)
    d = np.array(r[3:])
    return np.ascontiguousarray(np.broadcast_to(np.array(r[:3], float)[:, None], d.shape)), d


def scattered_rays(scene, n=3001):
    """Rays from points around the scene's objects in every direction (n: not a whole number of packets)."""
    rng = np.random.default_rng(7)
    lo, hi = scene.boxes.lo[scene.boxes.bounded], scene.boxes.hi[scene.boxes.bounded]
    a, b = lo.min(axis=0) - 1, hi.max(axis=0) + 1
    o = rng.uniform(a[:, None], b[:, None], (3, n))
    return o, rng.normal(size=(3, n))


def answers(entry, scene, o, d, mode, t_max, packet: bool, left=None):
    """(t, object, prim) of each ray; with `packet`, `left` (n,) gets 1 for each ray that left its packet."""
    from rtcli.compiled.pack import geometry, lanes  # numba: only where it is installed
    g, words = geometry(scene, tree=scene.wants_bvh)
    n = o.shape[1]
    out = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
    args = (g, np.ascontiguousarray(o), np.ascontiguousarray(d), np.full(n, 1e-9), np.full(n, t_max), mode, *out,
            np.empty(2 * words, np.int64))
    entry(*args, *((lanes(), np.zeros(n, np.int64) if left is None else left) if packet else ()))
    return out


@pytest.mark.parametrize("name", SCENES + ["ties"])
def test_packets_answer_as_one_ray_walks_do(name, tmp_path):
    scene = ties_scene(tmp_path) if name == "ties" else load_scene(str(ROOT / name))
    packets, single, found, leavers = *compiled_entries(), [], {}
    for o, d in (camera_rays(scene), scattered_rays(scene)):
        for mode, t_max in ((NEAREST, np.inf), (NEAREST_CASTER, np.inf), (ANY_CASTER, 2.5)):
            left = np.zeros(o.shape[1], np.int64)
            t, hit, prim = answers(packets, scene, o, d, mode, t_max, True, left)
            leavers[mode] = leavers.get(mode, 0) + left.sum()
            t1, hit1, prim1 = answers(single, scene, o, d, mode, t_max, False)
            if mode == ANY_CASTER:                    # any caster will do: only whether one was found
                assert np.array_equal(hit >= 0, hit1 >= 0), (name, mode)
                continue
            assert np.array_equal(t, t1) and np.array_equal(hit, hit1), (name, mode)
            assert np.array_equal(prim[hit >= 0], prim1[hit1 >= 0]), (name, mode)
            found += [hit1] if mode == NEAREST else []
    found = np.concatenate(found)
    assert (found >= 0).any() and (found < 0).any()            # the rays both hit and miss
    assert leavers[ANY_CASTER] == 0                            # a feeler never leaves: any caster will do
    if name in ("bench/torus100k.yaml", "bench/spheres1k.yaml"):
        assert leavers[NEAREST] > 0                            # scattered rays disagree, and leave


def test_the_ties_scene_has_ties(tmp_path):
    """Its camera rays meet spheres each drawn twice (two objects at the very same t), and the
    triangle drawn twice: every such hit is a tie, which the test above holds to the one-ray way."""
    scene = ties_scene(tmp_path)
    _, hit, _ = answers(compiled_entries()[1], scene, *camera_rays(scene), NEAREST, np.inf, False)
    assert ((hit >= 0) & (hit < 24)).sum() > 100 and (hit == 24).sum() > 100


VECTOR_CHECK = """
import re, sys
import numpy as np
from rtcli.compiled import packets
from rtcli.compiled.pack import geometry, lanes
from rtcli.kernels.variants import compiled
from rtcli.scenefile.load import load_scene
entry = compiled(packets.packet_rays)
g, words = geometry(load_scene(sys.argv[1]), tree=True)
n = 8
entry(g, np.zeros((3, n)), np.ones((3, n)), np.zeros(n), np.full(n, np.inf), 0, np.empty(n),
      np.empty(n, np.int64), np.empty(n, np.int64), np.empty(2 * words, np.int64), lanes(), np.zeros(n, np.int64))
for part in re.split(r"\\n(?=[^\\s.#][^\\n]*:\\n)", entry.inspect_asm(entry.signatures[0])):
    if "packet_walk" in part.split(":")[0]:
        print(" ".join(sorted(set(re.findall(r"^\\s+(v?(?:mul|sub|cmp\\w*|min|max)pd)\\s", part, re.M)))))
"""


@pytest.mark.slow
def test_the_walks_test_boxes_and_triangles_in_vector_instructions(tmp_path):
    """The machine code of both packet walks (the scene's tree, a mesh's) holds packed-double
    multiplies, subtractions, compares, minima and maxima: the lane loops of the slab test and of
    the triangle test became vector instructions. Compiled afresh (numba shows no machine code it
    loads from its cache)."""
    env = dict(os.environ, RTCLI_CACHE_DIR=str(tmp_path))
    run = subprocess.run([sys.executable, "-c", VECTOR_CHECK, str(ROOT / "bench/torus100k.yaml")], env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    walks = [set(line.split()) for line in run.stdout.splitlines()]
    assert len(walks) == 2, run.stdout
    for ops in walks:
        names = {op.lstrip("v") for op in ops}
        assert {"mulpd", "subpd", "minpd", "maxpd"} <= names and any(op.startswith("cmp") for op in names), ops
