"""The compiled engine (rtcli/fast/) against its oracle, the numpy core: the same pixels, the same ray counts.

The first test to run compiles the integrator (about 30 s) unless numba's cache has it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import without_avx512

from rtcli import compiled as fast
from rtcli.errors import RtcliError
from rtcli.kernels import variants
from rtcli.rendering.engine import AUTO_RAYS, choose
from rtcli.rendering.tiles import Job, render, render_tile
from rtcli.scenefile.load import load_scene

pytestmark = pytest.mark.skipif(not variants.ENABLED, reason="numba is not installed")

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted((ROOT / "scenes").glob("*.yaml")) + sorted((ROOT / "bench").glob("*.yaml"))
SUPPORTED = [p for p in SCENES if fast.unsupported(load_scene(str(p))) is None]


def both(scene, width=96, height=72, **job):
    """(numpy image, compiled image, numpy stats, compiled stats) of one scene (job: Job's options)."""
    a, sa = render(scene, Job(width, height, engine="numpy", **job))
    b, sb = render(scene, Job(width, height, engine="compiled", **job))
    return a, b, sa, sb


def test_every_scene_is_supported():
    assert SUPPORTED == SCENES and any(p.stem == "csg" for p in SUPPORTED)


def shape_scene(shape, seed: int):
    """One registered shape, turned and moved at random, glassy, mirrored and checkered, over a
    checkered floor, under a spot and an area light; the camera frames it."""
    from functools import partial

    from rtcli.core.camera import from_fov
    from rtcli.core.lights import PointLight
    from rtcli.core.materials import Material, MaterialTable
    from rtcli.core.scene import Scene, SceneObject
    from rtcli.core.textures import Checker
    from rtcli.core.transform import rotate, translate
    from rtcli.shapes.plane import Plane
    rng = np.random.default_rng(seed)
    placed = rotate(rng.normal(size=3), rng.uniform(0, 360)).then(translate([0, 1.5, 0]))
    box = SceneObject(1, "", shape, 1, placed).bounds()
    mid, size = ((box[0] + box[1]) / 2, np.linalg.norm(box[1] - box[0])) if box else (np.array([0, 1.5, 0]), 4.0)
    size = min(size, 12.0)
    checks = Checker(np.array([0.9, 0.9, 0.8]), np.array([0.2, 0.3, 0.6]), size / 6)
    materials = MaterialTable([Material(texture=checks), Material(
        diffuse=np.array([0.6, 0.3, 0.2]), specular=np.full(3, 0.5), shininess=40.0, reflection=np.full(3, 0.3),
        transmission=np.full(3, 0.4), ior=1.4, texture=checks)])
    floor = SceneObject(2, "floor", Plane((0, mid[1] - size, 0)), 0)
    eye = mid + size * np.array([0.9, 0.7, 1.6])
    lights = [PointLight(mid + size * np.array([1.0, 2, 1]), np.ones(3), np.array([1.0, 0, 0]),
                         np.array([-0.4, -0.8, -0.4]) / np.linalg.norm([0.4, 0.8, 0.4]), 0.8, 2.0),
              PointLight(mid + size * np.array([-1.5, 1.5, 0.5]), np.full(3, 0.5), np.array([1.0, 0, 0]),
                         area_u=np.array([size / 3, 0, 0]), area_v=np.array([0, 0, size / 3]), area_samples=2)]
    return Scene(partial(from_fov, eye, mid, [0, 1, 0], 40.0), [SceneObject(1, "", shape, 1, placed), floor],
                 materials, lights, eye=eye)


SHAPE_EXAMPLES = [(f"{key}{k}", shape) for key, cls in __import__("rtcli.shapes").shapes.SHAPES.items()
                  for k, shape in enumerate(cls.examples())]


@pytest.mark.parametrize("name, shape", SHAPE_EXAMPLES, ids=[n for n, _ in SHAPE_EXAMPLES])
def test_every_registered_shape_renders_the_same_in_both_engines(name, shape):
    """Every shape of the registry, through its examples: no scene file needed for a new shape."""
    scene = shape_scene(shape, len(name))
    ids, _ = render(scene, Job(64, 48, signature=True))
    assert (ids == 1).sum() > 20, "the shape must be in view"
    a, b, sa, sb = both(scene, 64, 48)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    assert (sa.shadow, sa.reflected, sa.refracted) == (sb.shadow, sb.reflected, sb.refracted)


@pytest.mark.parametrize("path", SUPPORTED, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_supported_scene_renders_the_same_pixels_and_rays(path):
    scene = load_scene(str(path))
    a, b, sa, sb = both(scene)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    assert (sa.primary, sa.shadow, sa.reflected, sa.refracted) == (sb.primary, sb.shadow, sb.reflected, sb.refracted)
    assert (sa.engine, sb.engine) == ("numpy", "compiled")


def test_colors_are_equal_to_the_last_bit(yaml_scene):
    """Before rounding to bytes: every sum and product is taken in the numpy core's order, and every
    elementary function is rtcli's own (rtcli/core/elementary.py)."""
    scene = load_scene(str(ROOT / "bench" / "quadrics.yaml"))
    i, j = np.meshgrid(np.arange(0, 640, 7), np.arange(0, 480, 5))
    job = Job(640, 480)
    a, _ = render_tile(scene, job, i.ravel(), j.ravel())
    b, _ = render_tile(scene, job, i.ravel(), j.ravel(), choose(scene, "compiled"))
    assert np.array_equal(a, b)


TRANSFORMED = """
camera: {eye: [0, 3, -9], look_at: [0, 0.5, 0], fov: 45}
ambient: [0.2, 0.2, 0.2]
render: {max_depth: 6, specular: SPEC}
lights:
  - {position: [4, 6, -5], color: [0.9, 0.9, 0.9], attenuation: [1, 0.02, 0.001]}
  - {position: [-3, 5, -2], color: [0.6, 0.5, 0.4], spot: {direction: [0.6, -1, 0.4], angle: 30, falloff: 4}}
  - {position: [0, 6, 1], color: [0.3, 0.3, 0.35], area: {u: [1.5, 0, 0], v: [0, 0.3, 1.2], samples: 3}}
materials:
  glass: {diffuse: 0.05, specular: 0.8, shininess: 50, reflection: 0.1, transmission: 0.85, ior: 1.45}
  mirror: {diffuse: 0.1, specular: 0.5, reflection: 0.7}
  checks: {texture: {checker: {colors: [[1, 1, 1], [0.1, 0.2, 0.6]], size: 0.5}}, emission: [0.05, 0, 0]}
objects:
  - {plane: {normal: [0.1, 1, 0], point: [0, -1, 0]}, material: checks}
  - {sphere: {}, material: glass, transform: [{scale: [1.2, 0.6, 0.9]}, {rotate: {axis: [1, 1, 0], degrees: 35}}, {translate: [-1.5, 0.4, 0]}]}
  - {box: {min: [-1, -0.5, -0.3], max: [0.6, 0.5, 0.8]}, material: mirror, transform: [{rotate: {axis: [0, 1, 0], degrees: 25}}, {scale: [-1, 1, 1]}, {translate: [1.8, 0, 1]}]}
  - {cylinder: {base: [0, -1, 0], top: [0.3, 1.2, 0.2], radius: 0.4}, material: checks, transform: [{translate: [0, 0, 2]}]}
  - {cone: {base: [0, 0, 0], top: [0, 1, 0], radius: 0.6, top_radius: 0.25}, material: glass, transform: [{scale: [1, 1.5, 1]}, {translate: [0.5, -0.9, -1.5]}]}
  - {cone: {radius: 0.5, capped: false}, transform: [{rotate: {axis: [1, 0, 0], degrees: -70}}, {translate: [-2.5, 1, 1.5]}]}
  - {box: {}, material: {diffuse: [0.8, 0.3, 0.2], shadow: false}, transform: [{scale: 0.3}, {translate: [0, 1.6, 0]}]}
  - {square: {}, material: mirror, transform: [{scale: 0.8}, {rotate: {axis: [0, 1, 0], degrees: 200}}, {translate: [-1, 0.5, 3]}]}
  - triangle:
      vertices: [[2, -1, 2.5], [3.5, -1, 3], [2.8, 1.5, 2.8]]
      normals: [[-1, 0.2, -1], [1, 0.3, -1], [0, 1, -0.5]]
    material: glass
  - {polygon: {vertices: [[-3, -1, 3], [-1.5, -1, 3], [-2.2, 0, 3], [-1.5, 1, 3], [-3, 1, 3]]}, material: checks}
  - {torus: {major: 0.5, minor: 0.2}, material: mirror, transform: [{rotate: {axis: [1, 0.3, 0], degrees: 60}}, {translate: [2.6, 1.7, -1.2]}]}
"""


@pytest.mark.parametrize("spec", ["phong", "blinn"])
@pytest.mark.parametrize("bvh", [False, True])
def test_transformed_shapes_glass_and_every_kind_of_light(yaml_scene, spec, bvh):
    """Every kind of shape the compiled engine has, most under transforms (a mirror one too),
    a smooth glass triangle and a concave polygon; attenuated, spot and area lights; with and
    without a BVH over the objects (both engines alike)."""
    scene = yaml_scene(TRANSFORMED.replace("SPEC", spec))
    assert scene.wants_bvh
    ids, _ = render(scene, Job(120, 90, signature=True))
    assert set(range(1, len(scene.objects) + 1)) <= set(np.unique(ids).tolist())    # each one in view
    a, b, sa, sb = both(scene, 120, 90, bvh=bvh)
    assert np.array_equal(a, b)
    assert sb.refracted > 0 and sb.reflected > 0 and sb.shadow > 0
    assert len(np.unique(b.reshape(-1, 3), axis=0)) > 1000          # a real picture, not a flat fill


GLASS = """
camera: {eye: [0, 2.5, -8], look_at: [0, 0.8, 0], fov: 40}
ambient: [0.2, 0.2, 0.2]
background: [0.3, 0.5, 0.8]
render: {max_depth: 7, medium_ior: MEDIUM, total_internal_reflection: TIR}
lights:
  - {position: [3, 6, -4], color: [0.9, 0.9, 0.9]}
  - {position: [-4, 5, 1], color: [0.4, 0.4, 0.5], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 2}}
materials:
  glass: {diffuse: 0.02, specular: 0.6, shininess: 80, reflection: 1, transmission: 1, ior: 1.5, fresnel: true, shadow: filter}
  tinted: {diffuse: 0.05, reflection: 0.1, transmission: [0.9, 0.5, 0.4], ior: 1.45, shadow: filter}
  air: {diffuse: 0, ambient: 0, transmission: 1, ior: 1.0, shadow: false}
  water: {diffuse: 0.02, ambient: 0, reflection: 0.05, transmission: [0.8, 0.9, 0.95], ior: 1.33, shadow: filter}
  checks: {texture: {checker: {colors: [[1, 1, 1], [0.2, 0.3, 0.3]], size: 0.5}}}
objects:
  - {plane: {point: [0, -0.5, 0]}, material: checks}
  - {sphere: {center: [-1.6, 1, 0], radius: 1}, material: glass}
  - {sphere: {center: [-1.6, 1.2, -0.2], radius: 0.4}, material: air}
  - {box: {min: [0.3, -0.5, -1], max: [2.6, 1.2, 1]}, material: water}
  - {sphere: {center: [1.4, 0.4, 0], radius: 0.5}, material: tinted}
  - {cylinder: {base: [0.8, -0.5, -2], top: [0.8, 1.5, -2], radius: 0.3}, material: glass}
  - {triangle: {vertices: [[-3, -0.5, 2], [-1, -0.5, 2.5], [-2, 2, 2.2]]}, material: tinted}
  - {sphere: {center: [2.5, 2.2, 2], radius: 0.4}}
  - {sphere: {center: [-2.8, 2.4, 1], radius: 0.3}, material: glass}
"""


@pytest.mark.parametrize("tir", ["drop", "reflect"])
@pytest.mark.parametrize("medium, bvh", [("1.0", True), ("1.1", False)])
def test_glass_media_fresnel_filtered_shadows(yaml_scene, tir, medium, bvh):
    """Nested media (an air bubble in Fresnel glass, a ball in a water tank, the camera's medium),
    total internal reflection dropped or reflected, shadows filtered through glass and water."""
    scene = yaml_scene(GLASS.replace("TIR", tir).replace("MEDIUM", medium))
    a, b, sa, sb = both(scene, 120, 90, bvh=bvh)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    assert (sa.shadow, sa.reflected, sa.refracted) == (sb.shadow, sb.reflected, sb.refracted)
    assert sb.refracted > 2000 and len(np.unique(b.reshape(-1, 3), axis=0)) > 1500


def test_samples_max_depth_block_size_and_workers(yaml_scene):
    scene = yaml_scene(TRANSFORMED.replace("SPEC", "phong"))
    scene.settings.samples, scene.settings.max_depth = 2, 3
    a, b, _, _ = both(scene, 64, 48, block_size=2)
    assert np.array_equal(a, b)
    c, _ = render(scene, Job(64, 48, block_size=2, tile=16, engine="compiled"), workers=2)
    assert np.array_equal(b, c)


def test_many_objects_go_through_the_scene_bvh(yaml_scene):
    rng = np.random.default_rng(5)
    balls = "\n".join(f"  - {{sphere: {{center: [{x:.3f}, {y:.3f}, {z:.3f}], radius: {r:.3f}}}, "
                      f"material: {{diffuse: [{x % 1:.2f}, 0.5, 0.5], reflection: {0.4 if k % 3 == 0 else 0}}}}}"
                      for k, (x, y, z, r) in enumerate(zip(*rng.uniform(-3, 3, (3, 60)), rng.uniform(0.1, 0.5, 60))))
    scene = yaml_scene(f"""
        camera: {{eye: [0, 0, -12], look_at: [0, 0, 0], fov: 40}}
        lights: [{{position: [5, 8, -8], color: [1, 1, 1]}}]
        objects:
        {balls}
        """.replace("\n        ", "\n"))
    assert fast.Compiled(scene, bvh=False).geometry.links.shape[0] == 1   # no BVH: objects in file order
    assert fast.Compiled(scene).geometry.links.shape[0] > 1
    a, b, _, _ = both(scene, 80, 80)
    assert np.array_equal(a, b)


def test_unsupported_names_what_the_compiled_engine_lacks():
    from rtcli.core.scene import SceneObject
    reasons = {p.stem: fast.unsupported(load_scene(str(p))) for p in SCENES}
    assert set(reasons.values()) == {None}
    scene = load_scene(str(ROOT / "scenes" / "whitted.yaml"))

    class Blob:
        pass
    scene.objects.append(SceneObject(len(scene.objects) + 1, "", Blob(), 0, kind="blob"))
    assert fast.unsupported(scene) == "blob objects"


def test_choose_falls_back_to_numpy_or_says_why(monkeypatch):
    csg = load_scene(str(ROOT / "scenes" / "csg.yaml"))
    whitted = load_scene(str(ROOT / "scenes" / "whitted.yaml"))
    assert isinstance(choose(csg, "auto"), fast.Compiled)
    assert isinstance(choose(csg, "compiled"), fast.Compiled)
    assert choose(whitted, "numpy") is None
    assert choose(whitted, "auto", rays=AUTO_RAYS - 1) is None     # small jobs: no numba start-up
    assert isinstance(choose(whitted, "auto"), fast.Compiled)
    monkeypatch.setattr(variants, "ENABLED", False)
    assert choose(whitted, "auto") is None
    with pytest.raises(RtcliError, match="numba is not installed"):
        choose(whitted, "compiled")


def test_a_source_change_drops_the_cached_machine_code(tmp_path, monkeypatch):
    """numba alone would keep machine code built from an older sphere.py inside the integrator's cache."""
    package = tmp_path / "rtcli"
    for folder in ("kernels", "core", "shapes", "compiled"):
        (package / folder / "__pycache__").mkdir(parents=True)
        (package / folder / "a.py").write_text(f"# {folder}\n")
    stale = [package / folder / "__pycache__" / "a.f-1.py311.nbi" for folder in ("core", "shapes", "compiled")]
    monkeypatch.setattr(fast, "PACKAGE", package)

    def cache(text):
        for f in stale:
            f.write_text(text)
        fast.drop_stale_cache()
        return [f.exists() for f in stale]
    assert cache("old") == [False] * 3
    assert cache("new") == [True] * 3              # same sources: the cache stays
    (package / "shapes" / "a.py").write_text("# a changed kernel\n")
    assert cache("newer") == [False] * 3


def test_image_textures_on_every_shape(yaml_scene, tmp_path):
    """(u, v) of every compiled shape, under transforms, tiled and clamped pictures."""
    rng = np.random.default_rng(2)
    from PIL import Image
    Image.fromarray(rng.integers(0, 256, (7, 5, 3), dtype=np.uint8)).save(tmp_path / "noise.png")
    scene = yaml_scene("""
        camera: {eye: [0, 3, -9], look_at: [0, 0.5, 0], fov: 50}
        lights: [{position: [4, 6, -5], color: [1, 1, 1]}]
        materials:
          tiled: {texture: {image: noise.png}}
          clamped: {texture: {image: noise.png, repeat: false}}
        objects:
          - {plane: {point: [0, -1, 0], normal: [0, 1, 0.2]}, material: tiled}
          - {sphere: {radius: 0.8}, material: clamped, transform: [{scale: [1, 1.3, 1]}, {rotate: {axis: [0, 1, 1], degrees: 40}}, {translate: [-2.2, 0.5, 0]}]}
          - {box: {min: [-0.5, -0.5, -0.5], max: [0.7, 0.4, 0.5]}, material: tiled, transform: [{rotate: {axis: [1, 1, 0], degrees: 35}}, {translate: [0, 0.2, -1]}]}
          - {cylinder: {base: [0, -0.8, 0], top: [0, 0.8, 0], radius: 0.5}, material: clamped, transform: [{rotate: {axis: [1, 0, 0], degrees: -35}}, {translate: [2.2, 0.3, 0]}]}
          - {cone: {base: [0, 0, 0], top: [0, 1, 0], radius: 0.6, top_radius: 0.3}, material: tiled, transform: [{rotate: {axis: [1, 0, 0], degrees: -60}}, {translate: [1, 1.8, 1]}]}
          - {square: {}, material: clamped, transform: [{translate: [-1, 1.8, 1.5]}]}
          - {triangle: {vertices: [[0.5, -1, 2], [2, -1, 2], [1.2, 0.5, 2]]}, material: tiled}
          - {polygon: {vertices: [[-3.5, -1, 2.5], [-2, -1, 2.5], [-2.6, 0, 2.5], [-2, 1, 2.5], [-3.5, 1, 2.5]]}, material: clamped}
          - {torus: {major: 0.5, minor: 0.25}, material: tiled, transform: [{rotate: {axis: [1, 0, 0], degrees: 70}}, {translate: [-1.5, -0.4, -1.5]}]}
        """)
    ids, _ = render(scene, Job(120, 90, signature=True))
    assert set(range(1, len(scene.objects) + 1)) <= set(np.unique(ids).tolist())
    a, b, _, _ = both(scene, 120, 90)
    assert np.array_equal(a, b)
    assert len(np.unique(b.reshape(-1, 3), axis=0)) > 2000


def test_texels_are_kept_as_bytes(yaml_scene, tmp_path):
    """A picture costs 3 bytes a texel, read as byte / 255; a scene's only picture is not copied."""
    from PIL import Image
    picture = np.random.default_rng(3).integers(0, 256, (40, 30, 3), dtype=np.uint8)
    Image.fromarray(picture).save(tmp_path / "p.png")
    scene = yaml_scene("""
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
        objects: [{square: {}, material: {texture: {image: p.png, repeat: false}}}]
        """)
    texels = scene.materials.texels
    assert texels.dtype == np.uint8 and texels.shape == (1200, 3) and np.array_equal(texels.reshape(40, 30, 3), picture)
    assert np.shares_memory(texels, scene.materials.materials[1].texture.texels)
    a, b, _, _ = both(scene, 64, 48)
    assert np.array_equal(a, b) and len(np.unique(a.reshape(-1, 3), axis=0)) > 100


@pytest.mark.parametrize("order", ["floor first", "floor last"])
def test_ties_with_the_floor_go_to_the_same_object(yaml_scene, order):
    """A glass cylinder's base cap and a polygon lie on the floor plane: coplanar surfaces, hit at
    the same t. Both engines give such a tie to the object listed first."""
    floor = "  - {plane: {}, material: {texture: {checker: {colors: [[1, 1, 1], [0.2, 0.2, 0.2]], size: 0.5}}}}"
    others = """
  - {cylinder: {base: [0, 0, 0], top: [0, 1.5, 0], radius: 0.7}, material: {diffuse: 0.05, transmission: 0.9, ior: 1.5}}
  - {polygon: {vertices: [[1, 0, -1], [2, 0, -1], [2, 0, 0], [1, 0, 0]]}, material: {diffuse: [0.9, 0.1, 0.1]}}"""
    objects = floor + others if order == "floor first" else others + "\n" + floor
    scene = yaml_scene("""
camera: {eye: [0, 2, 5], look_at: [0, 0.5, 0], fov: 45}
lights: [{position: [3, 5, 4]}]
objects:""" + ("\n" if order == "floor first" else "") + objects + "\n")
    a, b, sa, sb = both(scene, 96, 72)
    assert np.array_equal(a, b)
    assert sa.refracted == sb.refracted


def test_corner_normals_that_cancel_fall_back_to_the_face(yaml_scene):
    """At x = 0 the interpolated normal of this triangle is zero: both engines shade with the
    face normal there (the centre column of a 97-pixel image lands on it)."""
    scene = yaml_scene("""
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}
        background: [0.2, 0.4, 0.6]
        lights: [{position: [3, 5, 4]}]
        objects:
          - triangle:
              vertices: [[-1, -1, 0], [1, -1, 0], [-1, 1, 0]]
              normals: [[0, 0, 1], [0, 0, -1], [0, 0, 1]]
            material: {diffuse: 0.5, transmission: 0.5, reflection: 0.25, ior: 1.0}
        """)
    a, b, sa, sb = both(scene, 97, 73)
    assert np.array_equal(a, b) and sa.refracted == sb.refracted
    assert np.isfinite(scene.objects[0].shape.normal(np.zeros((1, 3)), np.array([0]))).all()


def test_loading_the_engine_skips_numbas_blas_lookup_and_leaves_no_trace():
    import subprocess
    import sys
    code = ("import sys; from rtcli.scenefile.load import load_scene; from rtcli.rendering.engine import choose; "
            "choose(load_scene('scenes/whitted.yaml'), 'compiled'); "
            "print('scipy.linalg' in sys.modules, 'scipy.linalg.cython_blas' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_cli_engine_option(tmp_path):
    from click.testing import CliRunner

    from rtcli.cli import main
    runner, out = CliRunner(), tmp_path / "out.png"
    for scene in ("whitted", "csg"):
        good = runner.invoke(main, ["render", str(ROOT / "scenes" / f"{scene}.yaml"), "-o", str(out), "--width", "40",
                                    "--height", "30", "--engine", "compiled", "--stats", "--workers", "1"])
        assert good.exit_code == 0 and out.exists() and "compiled engine" in good.output, good.output
        out.unlink()


# --- CSG: span lists one ray at a time, against the numpy engine's arrays ---
SOLIDS = ("sphere", "box", "cylinder", "cone", "torus", "plane")


def random_solid(rng, kind: str) -> dict:
    def r(lo, hi):
        return round(float(rng.uniform(lo, hi)), 3)
    return {"sphere": lambda: {"sphere": {"center": [r(-.4, .4), r(-.4, .4), r(-.4, .4)], "radius": r(.4, 1.1)}},
            "box": lambda: {"box": {"min": [r(-1, -.3), r(-1, -.3), r(-1, -.3)],
                                    "max": [r(.2, 1), r(.2, 1), r(.2, 1)]}},
            "cylinder": lambda: {"cylinder": {"base": [0, r(-1, -.5), 0], "top": [r(-.3, .3), r(.5, 1), 0],
                                              "radius": r(.2, .6)}},
            "cone": lambda: {"cone": {"radius": r(.4, 1), "top_radius": r(0, .3)}},
            "torus": lambda: {"torus": {"major": r(.5, .8), "minor": r(.15, .35)}},
            "plane": lambda: {"plane": {"normal": [r(-1, 1), r(.2, 1), r(-1, 1)], "point": [0, r(-.3, .3), 0]}},
            }[kind]()


def random_csg(rng, depth: int, kinds: list, solids=SOLIDS) -> dict:
    """A csg of 2-4 children: solids of every kind (`kinds` first), nested csgs, some transformed,
    some with a material of their own (glass, a mirror, a filtering tint, a checker). A plane (a
    half-space) only cuts: in an intersection, or carved out by a difference."""
    op = str(rng.choice(["union", "intersection", "difference"]))
    children = []
    for c in range(rng.integers(2, 5)):
        kind = kinds.pop() if kinds else str(rng.choice(solids))
        if kind == "plane" and (op == "union" or (op == "difference" and c == 0)):
            kinds.append(kind)
            kind = "sphere"
        child = ({"csg": random_csg(rng, depth - 1, kinds, solids)} if depth and rng.random() < 0.35
                 else random_solid(rng, kind))
        if rng.random() < 0.5:
            child["transform"] = [{"scale": [float(x) for x in np.round(rng.uniform(0.6, 1.4, 3), 2)]},
                                  {"rotate": {"axis": [float(x) for x in np.round(rng.normal(size=3), 2)],
                                              "degrees": int(rng.integers(0, 360))}},
                                  {"translate": [float(x) for x in np.round(rng.uniform(-.4, .4, 3), 2)]}]
        if rng.random() < 0.4:
            child["material"] = str(rng.choice(["glass", "mirror", "tint", "checks"]))
        children.append(child)
    return {op: children}


CSG_SCENE = """
camera: {eye: [1.1, 1.7, 3.3], look_at: [0.4, 0.2, -0.5], fov: 50}
ambient: [0.2, 0.2, 0.2]
render: {max_depth: 5}
lights:
  - {position: [4, 6, 3], color: [0.9, 0.9, 0.9]}
  - {position: [-3, 4, -1], color: [0.4, 0.4, 0.5], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 2}}
materials:
  glass: {diffuse: 0.05, specular: 0.6, shininess: 60, reflection: 0.1, transmission: 0.85, ior: 1.45, shadow: filter}
  mirror: {diffuse: 0.1, specular: 0.5, reflection: 0.6}
  tint: {diffuse: [0.2, 0.5, 0.3], transmission: [0.8, 0.4, 0.4], ior: 1.0, shadow: filter}
  checks: {texture: {checker: {colors: [[1, 1, 1], [0.6, 0.1, 0.1]], size: 0.25}}}
objects:
  - plane: {point: [0, -1.4, 0]}
    material: {texture: {checker: {colors: [[0.9, 0.9, 0.9], [0.2, 0.3, 0.5]], size: 0.5}}}
"""


def random_csg_scene(seed: int, solids) -> str:
    """Two random csgs (every solid of `solids` a leaf somewhere) on CSG_SCENE's floor, as YAML."""
    import yaml
    rng = np.random.default_rng(seed)
    kinds = list(rng.permutation(solids))
    objects = [{"csg": random_csg(rng, 2, kinds, solids), "material": {"diffuse": [0.8, 0.6, 0.3], "specular": 0.4},
                "transform": [{"rotate": {"axis": [0, 1, 0], "degrees": int(rng.integers(0, 360))}}]}
               for _ in range(2)]
    objects[1]["transform"].append({"translate": [1.2, 0.6, -1.5]})
    if kinds:
        objects[1]["csg"] = {"difference": [{"csg": objects[1]["csg"]}] + [random_solid(rng, kind) for kind in kinds]}
    return CSG_SCENE + "".join(f"  - {yaml.safe_dump(o, default_flow_style=True, width=1e9)}" for o in objects)


@pytest.mark.parametrize("seed, torus", [(0, True), (4, True), (11, True),
                                         (1, False), (3, False), (8, False), (9, False)])
def test_random_csg_trees_render_the_same_in_both_engines(yaml_scene, seed, torus):
    """Random trees of every solid (nested, children transformed and with materials of their own,
    glass inside glass, filtering shadows): the same bytes and the same rays in both engines. The
    torus's roots included."""
    scene = yaml_scene(random_csg_scene(seed, SOLIDS if torus else tuple(k for k in SOLIDS if k != "torus")))
    ids, _ = render(scene, Job(80, 60, signature=True))
    assert np.count_nonzero(ids == 2) > 100 and np.count_nonzero(ids == 3) > 100, "both csgs must be in view"
    a, b, sa, sb = both(scene, 80, 60)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    rays_a = np.array([sa.shadow, sa.reflected, sa.refracted])
    rays_b = np.array([sb.shadow, sb.reflected, sb.refracted])
    assert np.array_equal(rays_a, rays_b)


CPU_SENSITIVE = ["textures", "torus", "spot", "phong", "csg", "aquarium", "presets"]


def test_numpys_two_code_paths_and_both_engines_give_the_same_bytes(tmp_path):
    """Scenes whose pixels take powers (specular, spot cones, --gamma), arc sines and arc tangents
    (uv), cube roots (the torus) and rotations, and a random CSG tree with a torus: rendered by the
    numpy engine in a process whose numpy has no AVX-512 paths (SVML), and here by both engines."""
    (tmp_path / "random.yaml").write_text(random_csg_scene(11, SOLIDS))
    paths = [str(ROOT / "scenes" / f"{name}.yaml") for name in CPU_SENSITIVE] + [str(tmp_path / "random.yaml")]
    code = ("import sys, numpy as np; from rtcli.rendering.tiles import Job, render; from rtcli.scenefile.load import "
            "load_scene; from rtcli.core.display import to_8bit; "
            "[np.save(f'{sys.argv[1]}/{k}.npy', to_8bit(render(load_scene(p), Job(80, 60, engine='numpy'))[0], "
            "gamma=True)) for k, p in enumerate(sys.argv[2:])]")
    without_avx512(["-c", code, str(tmp_path), *paths])
    from rtcli.core.display import to_8bit
    for k, path in enumerate(paths):
        other = np.load(tmp_path / f"{k}.npy")
        for engine in ("numpy", "compiled"):
            image = to_8bit(render(load_scene(path), Job(80, 60, engine=engine))[0], gamma=True)
            differ = np.count_nonzero((image != other).any(axis=2))
            assert differ == 0, f"{Path(path).stem}, {engine} engine: {differ} pixels differ from numpy without AVX-512"


COINCIDENT = """
camera: {eye: EYE, look_at: [0, 0.5, 0], fov: 60}
ambient: [0.2, 0.2, 0.2]
lights:
  - {position: [3, 5, 4], color: [0.8, 0.8, 0.8]}
  - {position: [0, 0.4, 0], color: [0.3, 0.3, 0.3]}
materials:
  red: {diffuse: [0.8, 0.1, 0.1]}
  glass: {diffuse: 0.05, reflection: 0.1, transmission: 0.8, ior: 1.5}
objects:
  - {plane: {point: [0, -1, 0]}, material: {texture: {checker: {colors: [[1, 1, 1], [0.3, 0.3, 0.3]], size: 0.5}}}}
  - name: a glass shell with a hole, the eye and a light inside it
    material: {diffuse: 0.1, transmission: 0.7, ior: 1.2, shadow: filter}
    csg:
      difference:
        - {sphere: {radius: 3}}
        - {sphere: {radius: 2.6}}
        - {cylinder: {base: [0, 0, 0], top: [0, 0, 4], radius: 0.8}, material: red}
  - name: box minus boxes sharing its faces
    csg:
      difference:
        - {box: {}}
        - {box: {min: [0, -1, -1], max: [1, 1, 0]}, material: red}
        - {box: {min: [-1, 0.5, -1], max: [1, 1, 1]}, transform: [{translate: [0, 0, 0]}]}
    transform: [{scale: 0.5}, {translate: [-1, 0, 0]}]
  - name: a sphere minus itself, and touching boxes
    csg:
      union:
        - {csg: {difference: [{sphere: {radius: 0.4}}, {sphere: {radius: 0.4}, material: red}]}}
        - {box: {min: [0, 0, 0], max: [0.5, 0.5, 0.5]}}
        - {box: {min: [0.5, 0, 0], max: [1, 0.5, 0.5]}, material: red}
        - csg: {intersection: [{box: {}}, {box: {}, material: red}, {sphere: {radius: 1.3}}]}
          transform: [{scale: 0.3}, {translate: [0.5, 1, 0]}]
    transform: [{translate: [0.8, -0.2, 0.3]}]
  - name: a glass lens the refracted rays start inside
    csg:
      intersection:
        - {sphere: {center: [0, 0, -1], radius: 1.2}}
        - {sphere: {center: [0, 0, 1], radius: 1.2}}
    material: glass
    transform: [{translate: [0, 0.2, 1.5]}]
"""


@pytest.mark.parametrize("eye", ["[0, 0.5, 5]", "[1.2, 0.6, 2.5]"], ids=["outside", "inside the shell"])
def test_csg_coincident_surfaces_rays_from_inside_and_shadows(yaml_scene, eye):
    """Differences whose surfaces coincide (a box minus boxes sharing its faces, a sphere minus
    itself: zero-length spans), touching solids, nested intersections of equal boxes, rays that
    start inside a solid (the eye inside a shell, rays inside a lens), shadow feelers through a
    shell with a hole to a light inside it: the same bytes and rays in both engines."""
    scene = yaml_scene(COINCIDENT.replace("EYE", eye))
    ids, _ = render(scene, Job(96, 72, signature=True))
    assert np.count_nonzero(ids == 2) > 2000 and all(np.count_nonzero(ids == k) > 30 for k in (3, 4, 5)) \
        or np.all(ids == 2), "the csgs in view, or all around"
    a, b, sa, sb = both(scene, 96, 72)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    assert (sa.shadow, sa.reflected, sa.refracted) == (sb.shadow, sb.reflected, sb.refracted)


@pytest.mark.parametrize("seed", [3, 8])
def test_csg_hits_normals_and_materials_ray_by_ray(yaml_scene, seed):
    """query.csg_hit and csg_normals, one ray at a time, against the numpy engine's CSG on arrays:
    the same t (rays from outside and from inside, within t limits), leaf material and normals,
    to the last bit (no torus here: its roots may differ by ulps, tests/kernels/test_kernels.py)."""
    from rtcli.compiled import query
    from rtcli.compiled.pack import MATERIAL
    from rtcli.wavefront.intersect import to_object
    scene = yaml_scene(random_csg_scene(seed, tuple(k for k in SOLIDS if k != "torus")))
    engine = fast.Compiled(scene)
    g, stack = engine.geometry, engine.stack
    hit, normals = variants.compiled(query.csg_hit), variants.compiled(query.csg_normals)
    rng = np.random.default_rng(seed)
    n, found = 1500, 0
    for k in (1, 2):
        obj = scene.objects[k]
        o = rng.uniform(-3, 3, (3, n))
        o[:, n // 2:] *= 0.2                                 # many from inside the solids
        d = rng.normal(size=(3, n))
        t_min, t_max = np.where(rng.random(n) < 0.3, 0.05, 0.0), np.where(rng.random(n) < 0.3, 2.0, np.inf)
        o, d = to_object(obj, o, d)
        t, prim = obj.shape.hits(o, d, t_min, t_max)
        for i in range(n):
            t1, prim1 = hit(g, g.objects[k], *o[:, i], *d[:, i], t_min[i], t_max[i], stack, 0)
            assert t1 == t[i], f"ray {i}"
            if np.isfinite(t1):
                found += 1
                p = o[:, i:i + 1] + t1 * d[:, i:i + 1]
                leaf_material = g.leaves[prim1 % len(g.leaves), MATERIAL]
                assert leaf_material == obj.shape.material_of(prim[i:i + 1], obj.material)[0]
                ns, ng = obj.shape.normals_at(p, prim[i:i + 1])
                assert normals(g, prim1, *p[:, 0]) == (*ns[:, 0], *ng[:, 0])
    assert found > 400


def test_the_csg_scene_at_its_own_size():
    """scenes/csg.yaml (a die carved by spherical pips, a glass lens) at 480 x 320: the same bytes."""
    scene = load_scene(str(ROOT / "scenes" / "csg.yaml"))
    a, b, sa, sb = both(scene, 480, 320)
    assert np.array_equal(a, b), f"{np.count_nonzero((a != b).any(axis=2))} pixels differ"
    assert (sa.shadow, sa.reflected, sa.refracted) == (sb.shadow, sb.reflected, sb.refracted)


def test_auto_takes_the_compiled_engine_for_a_small_job_that_would_load_numba_anyway(monkeypatch):
    """Below AUTO_RAYS, `auto` stays on numpy for plain scenes, but a mesh (or a set of spheres)
    makes the numpy engine load compiled walks itself, so the compiled engine is taken (once
    it is cached)."""
    from rtcli.rendering.engine import prepare
    monkeypatch.setattr(fast, "ready_to_load", lambda: True)
    monkeypatch.setattr(fast, "starts_at_once", lambda: False)          # no machine code file
    small = AUTO_RAYS // 2
    for name, expected in (("scenes/whitted.yaml", None), ("bench/torus100k.yaml", fast.Compiled),
                           ("bench/spheres1k.yaml", fast.Compiled)):
        scene = load_scene(str(ROOT / name))
        engine, _ = prepare(scene, Job(64, 48, engine="auto"), small)
        assert (engine is None) if expected is None else isinstance(engine, expected), name
        assert prepare(scene, Job(64, 48, engine="numpy"), small)[0] is None


def test_auto_stays_on_numpy_for_a_small_job_before_the_first_compile(monkeypatch, tmp_path):
    """Uncached, the integrator would compile for a minute where the numpy engine's walks take
    seconds: a small mesh job stays on numpy. ready_to_load reads the cache it is given."""
    from rtcli.rendering.engine import prepare
    monkeypatch.setattr(fast, "ready_to_load", lambda: False)
    monkeypatch.setattr(fast, "starts_at_once", lambda: False)
    scene = load_scene(str(ROOT / "bench/torus100k.yaml"))
    assert prepare(scene, Job(64, 48, engine="auto"), AUTO_RAYS // 2)[0] is None
    env = {**os.environ, "RTCLI_CACHE_DIR": str(tmp_path)}
    ask = "from rtcli import compiled; print(compiled.ready_to_load())"
    done = subprocess.run([sys.executable, "-c", ask], env=env, capture_output=True, text=True, cwd=ROOT)
    assert done.stdout.strip() == "False", done.stderr
    assert not any(tmp_path.rglob("*.nbc"))                    # asking compiled nothing
