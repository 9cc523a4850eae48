"""`rtcli validate`: the object listing (--objects), the warnings on stderr, and --strict."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from rtcli.cli import main

CAM = "image: {width: 64, height: 48}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
LIGHT = "lights: [{position: [0, 5, 5]}]\n"


@pytest.fixture
def validate(tmp_path, monkeypatch):
    """Run `rtcli validate ARGS s.yaml` on the given text; returns the click Result."""
    monkeypatch.chdir(tmp_path)

    def run(text: str, *args: str):
        (tmp_path / "s.yaml").write_text(text)
        return CliRunner().invoke(main, ["validate", *args, "s.yaml"])
    return run


def warnings_of(result) -> list[str]:
    assert result.exit_code == 0, result.output
    return result.stderr.splitlines()


# --- the listing ---
def test_objects_lists_every_object_with_its_material_bounds_and_shadow(validate, tmp_path):
    (tmp_path / "quad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    result = validate(CAM + LIGHT +
                      "materials:\n  red: {diffuse: [1, 0, 0]}\n  glass: {transmission: 0.9, shadow: filter}\n"
                      "objects:\n"
                      "  - {name: floor, plane: {point: [0, -1, 0]}, material: {diffuse: 0.5}}\n"
                      "  - {name: ball, sphere: {radius: 0.5}, material: red}\n"
                      "  - {box: {}, material: glass, transform: [{scale: [1, 2, 3]}, {translate: [1, 0, 0]}]}\n"
                      "  - {name: quad, mesh: {file: quad.obj}}\n"
                      "  - group:\n      objects: [{name: inner, sphere: {center: [0, 0, -3]}}]\n"
                      "    material: red\n", "--objects")
    assert result.exit_code == 0, result.output
    assert result.stderr == ""
    assert result.stdout.splitlines()[1:] == [
        "id  name   shape   material  shadow  triangles  bounds",
        " 1  floor  plane   inline    true            -  unbounded",
        " 2  ball   sphere  red       true            -  [-0.5, -0.5, -0.5] .. [0.5, 0.5, 0.5]",
        " 3  -      box     glass     filter          -  [0, -2, -3] .. [2, 2, 3]",
        " 4  quad   mesh    default   true            2  [0, 0, 0] .. [1, 1, 0]",
        " 5  inner  sphere  red       true            -  [-1, -1, -4] .. [1, 1, -2]",
    ]


def test_validate_without_objects_prints_the_summary_alone(validate):
    result = validate(CAM + LIGHT + "objects: [{sphere: {}}]\n")
    assert result.exit_code == 0 and result.stderr == ""
    assert result.stdout == ("s.yaml: ok: 1 object (1 sphere), 1 light, 0 materials; 64x48, max_depth 5, "
                             "phong, samples 1\n")


# --- colors given as 0-255 values ---
@pytest.mark.parametrize("color, warned", [
    ("[255, 255, 255]", True),
    ("[255, 128, 0]", True),
    ("[2, 0.5, 0]", True),            # every channel above 1 is a whole number
    ("200", True),                    # a coefficient as one number
    ("[255.0, 0, 0]", False),         # a decimal point: more than 1 is meant
    ("[1.5, 2, 0]", False),
    ("[300, 0, 0]", False),           # not a byte
    ("[1, 0, 0]", False),
    ('"#ff8000"', False),
])
def test_a_color_like_0_255_values_is_a_warning(validate, color, warned):
    found = warnings_of(validate(CAM + LIGHT + f"objects:\n  - sphere: {{}}\n    material: {{diffuse: {color}}}\n"))
    assert bool(found) == warned, found


def test_the_color_warning_is_located_and_suggests_the_0_1_color(validate):
    #             "    material: {diffuse: [255, 128, 0]}": '[' at 25 of line 6
    found = warnings_of(validate(CAM + LIGHT + "objects:\n  - sphere: {}\n    material: {diffuse: [255, 128, 0]}\n"))
    assert found == ["s.yaml:6:25: objects[0].material.diffuse: warning: [255, 128, 0] looks like 0-255 values, "
                     'but colors run from 0 to 1 here: [1, 0.502, 0] or "#ff8000" (write 255.0 if more than 1 '
                     "is meant)"]


def test_a_light_color_and_the_background_are_checked_too(validate):
    found = warnings_of(validate(CAM + "lights: [{position: [0, 5, 5], color: [255, 255, 255]}]\n"
                                       "background: [30, 30, 40]\nobjects: [{sphere: {}}]\n"))
    #      "lights: [{position: [0, 5, 5], color: [255, 255, 255]}]": '[' at 39
    assert [line.split(": warning:")[0] for line in found] == ["s.yaml:3:39: lights[0].color",
                                                                "s.yaml:4:13: background"]


def test_many_0_255_colors_are_listed_up_to_a_count(validate):
    """25 spheres with a byte color: the first 20 warnings, then one line counting the other 5."""
    spheres = "".join(f"  - {{sphere: {{center: [{k}, 0, -5]}}, material: {{diffuse: [255, 0, 0]}}}}\n"
                      for k in range(25))
    found = warnings_of(validate(CAM + LIGHT + "objects:\n" + spheres))
    assert len(found) == 21 and found[-1].startswith("s.yaml:25:")
    assert found[-1].endswith("warning: 5 more colors that look like 0-255 values (the first 20 are above)")
    found = warnings_of(validate(CAM + LIGHT + "objects:\n" + spheres.split("\n", 4)[-1]))     # 21 of them
    assert found[-1].endswith("warning: 1 more color that looks like 0-255 values (the first 20 are above)")


# --- lights, camera, objects ---
def test_no_lights(validate):
    assert warnings_of(validate(CAM + "objects: [{sphere: {}}]\n")) == [
        "s.yaml:1:1: lights: warning: no lights: only ambient light and emission show (a light is "
        "{position: [x, y, z]})"]


def test_no_objects(validate):
    assert warnings_of(validate(CAM + LIGHT + "objects: []\n")) == [
        "s.yaml:4:10: objects: warning: no objects: the image is the background"]


def test_a_camera_that_sees_no_object(validate):
    text = "camera: {eye: [0, 0, 5], look_at: [0, 0, 10]}\n" + LIGHT + "objects: [{sphere: {}}]\n"
    assert warnings_of(validate(text)) == [
        "s.yaml:1:9: camera: warning: the camera sees no object: every pixel of a signature render is "
        "background (is look_at toward the objects?)"]


def test_a_small_object_is_found_by_the_larger_signature(validate):
    """A ball too small for the 64-pixel signature's rays is found by the larger one: no warning."""
    text = ("image: {width: 512, height: 512}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40}\n" + LIGHT +
            "objects: [{sphere: {center: [0.0147, 0.0147, 0], radius: 0.006}}]\n")
    assert warnings_of(validate(text)) == []


LAMP = "lights: [{position: [0.2, 0, 0]}]\n"


@pytest.mark.parametrize("obj, warned", [
    ("{name: shade, sphere: {}}", True),
    ("{box: {}, transform: [{scale: 0.5}, {rotate: {axis: [0, 0, 1], degrees: 45}}]}", True),
    ("{name: shade, sphere: {}, material: {shadow: false}}", False),       # a glowing bulb's glass
    ("{name: shade, sphere: {}, material: {shadow: filter, transmission: 0.9}}", False),
    ("{sphere: {center: [3, 0, 0]}}", False),
    ("{cylinder: {capped: false}, transform: [{scale: 2}]}", False),       # open: not closed
    ("{plane: {normal: [-1, 0, 0]}}", False),                            # unbounded
])
def test_a_light_inside_a_closed_object(validate, obj, warned):
    found = [w for w in warnings_of(validate(CAM + LAMP + f"objects: [{obj}, {{sphere: {{center: [0, 0, -3]}}}}]\n"))
             if "inside" in w]
    assert bool(found) == warned, found


def test_the_light_inside_warning_names_the_light_and_the_object(validate):
    found = warnings_of(validate(CAM + LAMP + "objects: [{name: shade, sphere: {}}]\n"))
    assert found == ["s.yaml:3:10: lights[0]: warning: the light is inside object 1 (shade, a sphere), which casts "
                     "full shadows: it lights nothing outside it"]


@pytest.mark.parametrize("light, warned", [
    ("{position: [0, 5, 0], attenuation: [1, 0, 0.1]}", True),       # 1 / (1 + 0.1 r^2) < 1/255 at r = 995
    ("{position: [0, 5, 0], attenuation: [1, 0, 0.0001]}", False),    # 1 / 100 at r = 995
    ("{position: [0, 5, 0]}", False),                                 # no attenuation: everywhere
    ("{position: [0, 5, 0], color: [10.0, 10.0, 10.0], attenuation: [1, 0, 0.0025]}", False),
    ("{position: [0, 5, 0], spot: {direction: [1, 0, 0], angle: 10}}", True),      # the cone points away
    ("{position: [0, 5, 0], spot: {direction: [-1, 0, 0], angle: 10}}", False),
    ("{position: [-1200, 5, 0], attenuation: [1, 0, 0.1], area: {u: [400, 0, 0], v: [0, 0, 1]}}", False),
])
def test_an_object_out_of_every_lights_reach(validate, light, warned):
    text = (CAM + f"lights: [{light}]\n" +
            "objects:\n  - {sphere: {}}\n  - {name: far, sphere: {center: [-1000, 0, 0]}}\n")
    found = [w for w in warnings_of(validate(text)) if "objects[1]" in w]
    assert found == (["s.yaml:6:5: objects[1]: warning: no light reaches it: each light's attenuated intensity at "
                      "its box is below 1/255, or a spot light's cone misses it"] if warned else []), found


def test_an_emitting_object_needs_no_light(validate):
    text = CAM + ("lights: [{position: [0, 5, 0], attenuation: [1, 0, 0.1]}]\nobjects:\n  - {sphere: {}}\n"
                  "  - {sphere: {center: [-1000, 0, 0]}, material: {emission: [0.5, 0.5, 0.5]}}\n")
    assert warnings_of(validate(text)) == []


def test_many_warnings_of_one_kind_are_counted_after_the_first_twenty(validate):
    far = "".join(f"  - {{sphere: {{center: [-1000, {3 * k}, 0]}}}}\n" for k in range(25))
    found = warnings_of(validate(CAM + "lights: [{position: [0, 5, 0], attenuation: [0, 0, 1]}]\nobjects:\n"
                                       "  - {sphere: {}}\n" + far))
    assert len(found) == 21 and all("no light reaches it" in w for w in found[:20])
    assert found[20] == ("s.yaml:5:3: objects: warning: 5 more objects that no light reaches "
                         "(the first 20 are above)")


# --- --strict ---
def test_strict_makes_the_first_warning_an_error(validate, tmp_path):
    result = validate(CAM + "background: [30, 30, 40]\nobjects: [{sphere: {}}]\n", "--strict", "--objects")
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr == ("error: s.yaml:3:13: background: [30, 30, 40] looks like 0-255 values, but colors run "
                             'from 0 to 1 here: [0.118, 0.118, 0.157] or "#1e1e28" (write 30.0 if more than 1 is '
                             "meant) (and 1 more warning)\n")


def test_strict_passes_a_scene_without_warnings(validate):
    result = validate(CAM + LIGHT + "objects: [{sphere: {}}]\n", "--strict")
    assert result.exit_code == 0 and result.stderr == ""
