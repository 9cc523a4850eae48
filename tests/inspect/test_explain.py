"""rtcli explain: the ray tree of a pixel, term by term.

The root must be the rendered pixel (both engines, every scene in scenes/), every node must
add up from the terms it shows, and a tree missing any one term must not add up.
"""

from __future__ import annotations

import functools
import json
import math
import zlib
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import rtcli
from rtcli import compiled
from rtcli.cli import main
from rtcli.inspect.explain import Recorder
from rtcli.rendering.engine import choose
from rtcli.rendering.tiles import Job, render_tile

SCENES = sorted(str(p) for p in (Path(__file__).parents[2] / "scenes").glob("*.yaml"))
PIXELS = 12


@functools.lru_cache(maxsize=None)
def explained(path: str, samples: int | None = None):
    """A small render's scene, its pixels, their explanations and the pixels as both engines render them."""
    scene = rtcli.load_scene(path, width=40, samples=samples)
    model = scene.model
    w, h = model.settings.width, model.settings.height
    rng = np.random.default_rng(zlib.crc32(Path(path).name.encode()))      # the same wherever the clone is
    xs = np.concatenate([[0, w - 1, w // 2], rng.integers(0, w, PIXELS - 3)])
    ys = np.concatenate([[0, h - 1, h // 2], rng.integers(0, h, PIXELS - 3)])
    explanations = [rtcli.explain(scene, int(x), int(y)) for x, y in zip(xs, ys)]
    job = Job(w, h)
    numpy_pixels = render_tile(model, job, xs, ys)[0]
    engine = choose(model, "compiled" if compiled.unsupported(model) is None else "numpy", bvh=True)
    compiled_pixels = render_tile(model, job, xs, ys, engine)[0] if engine else None
    return explanations, numpy_pixels, compiled_pixels


CASES = [(path, None) for path in SCENES] + [(p, 2) for p in SCENES if Path(p).stem in ("lights", "textures")]


@pytest.mark.parametrize("path, samples", CASES, ids=lambda v: Path(v).stem if isinstance(v, str) else str(v))
def test_the_root_is_the_rendered_pixel(path, samples):
    explanations, numpy_pixels, compiled_pixels = explained(path, samples)
    values = np.array([e.value for e in explanations])
    np.testing.assert_array_equal(values, numpy_pixels)
    if compiled_pixels is not None:
        np.testing.assert_allclose(values, compiled_pixels, rtol=0, atol=1e-12)
    for e in explanations:
        assert len(e.trees) == e.samples ** 2 == (samples or 1) ** 2


@pytest.mark.parametrize("path, samples", CASES, ids=lambda v: Path(v).stem if isinstance(v, str) else str(v))
def test_every_ray_adds_up_from_the_terms_it_shows(path, samples):
    explanations = explained(path, samples)[0]
    nodes = [node for e in explanations for tree in e.trees for node in tree.walk()]
    for node in nodes:
        np.testing.assert_array_equal(node.total(), node.value)
    assert any(node.hit is not None for node in nodes)


WHITTED = str(Path(__file__).parents[2] / "scenes" / "whitted.yaml")


def test_a_tree_missing_any_one_term_does_not_add_up():
    """Take away any term (one too small to change its ray's sum in floating point aside)."""
    tree = rtcli.explain(WHITTED, 160, 120, width=320).trees[0]      # the glass ball: lights, a mirror and a refracted ray
    removed = 0

    def visible(node, term) -> bool:
        return bool((np.abs(term) > 1e-9 * np.abs(node.value)).any())

    for node in tree.walk():
        for light in node.lights:
            for sample in light.samples:
                for k in range(len(sample.terms)):
                    term = sample.terms.pop(k)
                    if visible(node, term):
                        assert not np.array_equal(node.total(), node.value)
                        removed += 1
                    sample.terms.insert(k, term)
        for k in range(len(node.children)):
            child = node.children.pop(k)
            if visible(node, child.weight * child.total()):
                assert not np.array_equal(node.total(), node.value)
                removed += 1
            node.children.insert(k, child)
        if node.hit is not None and visible(node, node.ambient):
            saved, node.ambient = node.ambient, np.zeros(3)
            assert not np.array_equal(node.total(), node.value)
            node.ambient, removed = saved, removed + 1
    assert removed >= 10
    for node in tree.walk():
        np.testing.assert_array_equal(node.total(), node.value)


def test_a_recorder_that_drops_the_specular_term_is_caught(monkeypatch):
    forget = Recorder.light

    def light(self, index, cell, q, L, r, NL, start, through, lit, terms, hl, cos, shine):
        forget(self, index, cell, q, L, r, NL, start, through, lit, terms, hl[:0], cos, shine)
    monkeypatch.setattr(Recorder, "light", light)
    tree = rtcli.explain(SPHERE, 10, 10).trees[0]
    assert not np.allclose(tree.total(), tree.value)


SPHERE = """
image: {width: 21, height: 21}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 30}
ambient: [0.2, 0.2, 0.2]
lights: [{position: [0, 4, 4], color: [1, 0.5, 0.25], attenuation: [1, 0.5, 0.25]}]
objects:
  - name: ball
    sphere: {radius: 1}
    material: {ambient: [0.1, 0.2, 0.3], diffuse: [0.5, 0.6, 0.7], specular: 0.4, shininess: 10}
"""


def test_the_terms_are_the_lecture_notes_formulas():
    e = rtcli.explain(SPHERE, 10, 10)
    ray = e.trees[0]
    h = ray.hit
    assert (h.object, h.name, h.shape, h.entering) == (1, "ball", "sphere", True)
    assert h.t == pytest.approx(4.0) and h.point == pytest.approx([0, 0, 1])
    assert h.normal == pytest.approx([0, 0, 1]) and h.geometric == pytest.approx([0, 0, 1])
    assert ray.ambient_term == pytest.approx([0.02, 0.04, 0.06])                  # ka Ia T
    (light,) = ray.lights
    (s,) = light.samples
    L = np.array([0, 4, 3]) / 5                                                    # from (0, 0, 1) to (0, 4, 4)
    assert s.L == pytest.approx(L) and s.r == pytest.approx(5) and s.NL == pytest.approx(0.6)
    assert s.attenuation == pytest.approx(1 / (1 + 0.5 * 5 + 0.25 * 25)) and s.spot == 1
    assert s.feeler.state == "clear"
    I = np.array([1, 0.5, 0.25])
    assert s.diffuse == pytest.approx(s.attenuation * 0.6 * I * [0.5, 0.6, 0.7])
    R = 2 * 0.6 * np.array([0, 0, 1]) - L                                          # R = 2 (N.L) N - L; V = +z
    assert s.cos == pytest.approx(R[2])
    assert s.specular == pytest.approx(s.attenuation * R[2] ** 10 * I * 0.4)
    assert ray.value == pytest.approx(ray.ambient_term + s.diffuse + s.specular)
    assert e.value == pytest.approx(ray.value) and tuple(e.byte) == tuple(np.rint(np.clip(e.value, 0, 1) * 255))


SHADOW = """
image: {width: 21, height: 21}
camera: {eye: [0, 6, 6], look_at: [0, 0, 0], fov: 20}
lights:
  - {position: [0, 10, 0]}
  - {position: [-8, 8, 0], spot: {direction: [1, 0, 0], angle: 10}}
  - {position: [0, 10, 0], area: {u: [1, 0, 0], v: [0, 0, 1], samples: 3}}
objects:
  - {name: floor, plane: {point: [0, 0, 0], normal: [0, 1, 0]}}
  - {name: blocker, sphere: {center: [0, 5, 0], radius: 1}}
"""


def test_feelers_name_their_blocker_and_lights_say_why_they_are_dark():
    e = rtcli.explain(SHADOW, 10, 10)
    ray = e.trees[0]
    assert ray.hit.name == "floor" and ray.hit.point == pytest.approx([0, 0, 0], abs=1e-9)
    point, spot, area = ray.lights
    (s,) = point.samples
    assert s.feeler.state == "blocked" and (s.feeler.blocker, s.feeler.blocker_name) == (2, "blocker")
    assert s.feeler.blocker_t == pytest.approx(0.4, abs=1e-6)                    # the ball's bottom, y = 4, of 10
    assert not s.lit and not s.diffuse.any()
    assert spot.kind == "spot" and spot.samples[0].spot == 0                       # the spot points along +x, far off
    assert area.kind == "area" and len(area.samples) == 9
    assert all(a.feeler.state == "blocked" and a.feeler.blocker == 2 for a in area.samples)
    text = e.text()
    assert "feeler blocked by #2 blocker at t = 0.4" in text
    assert "spot 0 (outside the cone)" in text
    assert "9 samples: 0 lit, 9 in shadow (by #2 blocker), 0 facing away" in text


GLASS = """
image: {width: 21, height: 21}
camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 30}
background: [0.2, 0.3, 0.4]
objects:
  - name: pane
    box: {min: [-1, -1, -0.5], max: [1, 1, 0.5]}
    material: {diffuse: 0, transmission: 0.9, reflection: 0.05, ior: 1.5, shadow: false}
    transform: [{rotate: {axis: [0, 1, 0], degrees: 30}}]
"""


def test_glass_shows_snell_and_total_internal_reflection():
    ray = rtcli.explain(GLASS, 10, 10).trees[0]
    g = ray.glass
    assert (g.n1, g.n2, g.tir) == (1.0, 1.5, False)
    assert g.theta_i == pytest.approx(30)
    assert 1.0 * math.sin(math.radians(g.theta_i)) == pytest.approx(1.5 * math.sin(math.radians(g.theta_t)))
    kinds = [c.kind for c in ray.children]
    assert kinds == ["reflected", "refracted"]
    inside = ray.children[1]
    assert inside.hit.entering is False and inside.glass.n1 == 1.5 and inside.glass.n2 == 1.0
    steep = rtcli.explain(GLASS.replace("degrees: 30", "degrees: 60"), 10, 10).trees[0].children[1]
    # inside at 35.3 deg against a face turned 60 deg... the other face: past the critical angle, 41.8 deg
    deep = [n for n in steep.walk() if n.glass is not None and n.glass.tir]
    assert deep and deep[0].glass.theta_t is None and deep[0].glass.R == 1
    assert "total internal reflection" in rtcli.explain(GLASS.replace("degrees: 30", "degrees: 60"), 10, 10).text()


def test_glass_names_what_weighs_its_rays_fresnel_or_the_given_kr_and_kt():
    plain = rtcli.explain(GLASS, 10, 10)
    fresnel = rtcli.explain(GLASS.replace("shadow: false}", "shadow: false, fresnel: true}"), 10, 10)
    assert (plain.trees[0].glass.fresnel, fresnel.trees[0].glass.fresnel) == (False, True)
    assert "weights kr and kt as given (fresnel: false)" in plain.text() and "Fresnel R" not in plain.text()
    R = fresnel.trees[0].glass.R
    assert f"Fresnel R {R:.6g}" in fresnel.text() and "as given" not in fresnel.text()
    assert fresnel.trees[0].children[0].weight == pytest.approx(0.05 * R)   # kr R, as the text says


def test_misses_and_max_depth_say_so():
    e = rtcli.explain(SPHERE, 0, 0)
    assert e.trees[0].hit is None and e.value.tolist() == [0, 0, 0]
    assert "misses every object: the background (0, 0, 0)" in e.text()
    one = rtcli.explain(GLASS, 10, 10, max_depth=1)
    assert one.trees[0].stopped and not one.trees[0].children
    assert "max_depth 1 reached: no reflected or refracted ray" in one.text()


def test_explain_command_text_json_and_errors(tmp_path):
    path = tmp_path / "ball.yaml"
    path.write_text(SPHERE)
    run = lambda *args, **kw: CliRunner().invoke(main, ["explain", str(path), *args], **kw)   # noqa: E731
    text = run("10", "10")
    assert text.exit_code == 0, text.output
    value = rtcli.explain(SPHERE, 10, 10).value
    lines = text.output.splitlines()
    assert lines[0].startswith("pixel (10, 10) of 21x21 = (") and "\x1b[" not in text.output
    assert any(line.strip().startswith("diffuse  w (N.L) I kd T") for line in lines)
    assert any("specular w (R.V)^n I ks" in line and "R.V 0.6" in line for line in lines)
    data = json.loads(run("10", "10", "--json").output)
    assert data["value"] == value.tolist() and data["samples"][0]["ray"]["hit"]["name"] == "ball"
    assert data["samples"][0]["ray"]["lights"][0]["samples"][0]["feeler"]["state"] == "clear"
    colored = run("10", "10", color=True)
    assert "\x1b[" in colored.output and "\x1b[" not in run("10", "10", color=True, env={"NO_COLOR": "1"}).output
    many = run("10", "10", "--samples", "2", "--all-samples")
    assert "the mean of 4 samples" in many.output and "sample 3 at (" in many.output
    assert len(json.loads(run("10", "10", "--samples", "2", "--json").output)["samples"]) == 4
    for args, message in [(("21", "0"), "pixel (21, 0) is outside the 21x21 image: x goes from 0 to 20"),
                          (("-1", "3"), "pixel (-1, 3) is outside the 21x21 image"),
                          (("1", "1", "--sample", "1"), "it has 1 (0 to 0)"),
                          (("1", "1", "--sample", "0", "--all-samples"), "--sample and --all-samples go one at a time")]:
        result = run(*args)
        assert result.exit_code == 2 and message in result.output and "Traceback" not in result.output
