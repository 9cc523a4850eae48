"""Tests for rtcli.scenefile.build / build_objects: scene checks with exact located messages, and what loads.

Every expected message is `scene.yaml:line:col: key.path: message`; columns are
1-based and counted by hand (the comment under a YAML line marks the column).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import scene_from_yaml

from rtcli.core import camera as cameras
from rtcli.errors import SceneError
from rtcli.shapes import SHAPES

CAM = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"


def error_of(text: str, tmp_path=None) -> str:
    """The one-line SceneError message of building `text` (shown as scene.yaml unless written to tmp_path)."""
    with pytest.raises(SceneError) as e:
        scene_from_yaml(text, tmp_path)
    return str(e.value)


def material_of(scene, k: int = 0):
    """The Material of object k."""
    return scene.materials.materials[scene.objects[k].material]


def obj(shape_line: str) -> str:
    """CAM plus one object on line 3: `  - <shape_line>` (its text starts at column 5)."""
    return CAM + "objects:\n  - " + shape_line + "\n"


# --- unknown keys (with a did-you-mean hint and the keys allowed there) ---
TOP_KEYS = "version, include, image, camera, background, ambient, render, lights, materials, objects, animation"
CAMERA_KEYS = "eye, look_at, up, fov, focal, window, screen, transform"
MATERIAL_KEYS = ("ambient, diffuse, specular, shininess, emission, reflection, transmission, ior, shadow, "
                 "fresnel, texture, preset")
UNKNOWN = {
    "top": (CAM + "objcts: []\n",
            f"scene.yaml:2:1: objcts: unknown key (did you mean 'objects'?); allowed here: {TOP_KEYS}"),
    #        camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fovy: 30}
    #                                                     ^ 46
    "camera": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fovy: 30}\n",
               f"scene.yaml:1:46: camera.fovy: unknown key (did you mean 'fov'?); allowed here: {CAMERA_KEYS}"),
    "light": (CAM + "lights:\n  - position: [1, 2, 3]\n    colour: [1, 1, 1]\n",
              "scene.yaml:4:5: lights[0].colour: unknown key (did you mean 'color'?); "
              "allowed here: position, color, attenuation, spot, area"),
    "material": (CAM + "materials:\n  red:\n    difuse: 0.5\n",
                 "scene.yaml:4:5: materials.red.difuse: unknown key (did you mean 'diffuse'?); "
                 f"allowed here: {MATERIAL_KEYS}"),
    "object": (obj("sphere: {}\n    materail: red"),
               "scene.yaml:4:5: objects[0].materail: unknown key (did you mean 'material'?); "
               "allowed here: name, transform, material, sphere"),
    #            "  - sphere: {raduis: 2}": 'raduis' at 14
    "shape": (obj("sphere: {raduis: 2}"),
              "scene.yaml:3:14: objects[0].sphere.raduis: unknown key (did you mean 'radius'?); "
              "allowed here: center, radius"),
    #            "  - square: {size: 2}": 'size' at 14
    "shape_without_keys": (obj("square: {size: 2}"),
                           "scene.yaml:3:14: objects[0].square.size: unknown key; no keys are allowed here"),
    #            "    transform: [{rotation: ...": 'rotation' at 18
    "transform_step": (obj("sphere: {}\n    transform: [{rotation: {axis: [0, 1, 0], degrees: 30}}]"),
                       "scene.yaml:4:18: objects[0].transform[0].rotation: unknown key (did you mean 'rotate'?); "
                       "allowed here: scale, rotate, translate, matrix"),
    #            "  - csg: {unoin: ...": 'unoin' at 11
    "csg_operation": (obj("csg: {unoin: [{sphere: {}}, {box: {}}]}"),
                      "scene.yaml:3:11: objects[0].csg.unoin: unknown key (did you mean 'union'?); "
                      "allowed here: union, intersection, difference"),
    #            "    material: {texture: {checkr: ...": 'checkr' at 26
    "texture_kind": (obj("sphere: {}\n    material: {texture: {checkr: {colors: [[1, 1, 1], [0, 0, 0]]}}}"),
                     "scene.yaml:4:26: objects[0].material.texture.checkr: unknown key (did you mean 'checker'?); "
                     "allowed here: checker, image"),
}


@pytest.mark.parametrize("text, expected", UNKNOWN.values(), ids=UNKNOWN.keys())
def test_unknown_key(text, expected):
    """An unknown key anywhere is reported at the key, with a did-you-mean hint and the keys allowed there."""
    assert error_of(text) == expected


# --- the lecture notes' names ---
NOTES = {
    #            "  window: {wl: -1, ...": 'wl' at 12
    "wl": ("camera:\n  eye: [0, 0, 5]\n  look_at: [0, 0, 0]\n  window: {wl: -1, wr: 1, wt: 1, wb: -1}\n",
           "scene.yaml:4:12: camera.window.wl: unknown key (the notes' wl is 'left' in rtcli); "
           "allowed here: left, right, top, bottom"),
    "f": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], f: 2, window: {left: -1, right: 1, top: 1, bottom: -1}}\n",
          f"scene.yaml:1:46: camera.f: unknown key (the notes' f is 'focal' in rtcli); allowed here: {CAMERA_KEYS}"),
    #            "camera: {position: ...": 'position' at 10, reported before the missing eye
    "position": ("camera: {position: [0, 0, 5], look_at: [0, 0, 0]}\n",
                 "scene.yaml:1:10: camera.position: unknown key (the notes' position is 'eye' in rtcli); "
                 f"allowed here: {CAMERA_KEYS}"),
    "lookat": ("camera: {eye: [0, 0, 5], lookat: [0, 0, 0]}\n",
               "scene.yaml:1:26: camera.lookat: unknown key (the notes' lookat is 'look_at' in rtcli); "
               f"allowed here: {CAMERA_KEYS}"),
    #            "  red: {kd: ...": 'kd' at 9
    "kd": (CAM + "materials:\n  red: {kd: [1, 0, 0]}\n",
           f"scene.yaml:3:9: materials.red.kd: unknown key (the notes' kd is 'diffuse' in rtcli); "
           f"allowed here: {MATERIAL_KEYS}"),
    "ka": (CAM + "materials:\n  red: {ka: 0.1}\n",
           f"scene.yaml:3:9: materials.red.ka: unknown key (the notes' ka is 'ambient' in rtcli); "
           f"allowed here: {MATERIAL_KEYS}"),
    "ks": (CAM + "materials:\n  red: {ks: 0.1}\n",
           f"scene.yaml:3:9: materials.red.ks: unknown key (the notes' ks is 'specular' in rtcli); "
           f"allowed here: {MATERIAL_KEYS}"),
    "exponent": (CAM + "materials:\n  red: {exponent: 10}\n",
                 f"scene.yaml:3:9: materials.red.exponent: unknown key (the notes' exponent is 'shininess' in "
                 f"rtcli); allowed here: {MATERIAL_KEYS}"),
    "color_in_a_material": (CAM + "materials:\n  red: {color: [1, 0, 0]}\n",
                            f"scene.yaml:3:9: materials.red.color: unknown key (the notes' color is 'diffuse' "
                            f"in rtcli); allowed here: {MATERIAL_KEYS}"),
    "color_on_an_object": (obj("sphere: {}\n    color: [1, 0, 0]"),
                           "scene.yaml:4:5: objects[0].color: unknown key (the notes' color is 'diffuse' in rtcli, "
                           "a key of the object's material: material: {diffuse: ...}); "
                           "allowed here: name, transform, material, sphere"),
    "diffuse_on_an_object": (obj("sphere: {}\n    diffuse: 0.5"),
                             "scene.yaml:4:5: objects[0].diffuse: unknown key (diffuse is a key of the object's "
                             "material: material: {diffuse: ...}); allowed here: name, transform, material, sphere"),
    #            "    transform: [{rotate: {axis: [0, 1, 0], angle: 30}}]": 'angle' at 44, before the missing degrees
    "angle": (obj("sphere: {}\n    transform: [{rotate: {axis: [0, 1, 0], angle: 30}}]"),
              "scene.yaml:4:44: objects[0].transform[0].rotate.angle: unknown key (the notes' angle is 'degrees' "
              "in rtcli); allowed here: axis, degrees"),
    #            "    transform: [{rotate: {angle: 30}}]": 'angle' at 27, before the missing axis too
    "angle_alone": (obj("sphere: {}\n    transform: [{rotate: {angle: 30}}]"),
                    "scene.yaml:4:27: objects[0].transform[0].rotate.angle: unknown key (the notes' angle is "
                    "'degrees' in rtcli); allowed here: axis, degrees"),
}


@pytest.mark.parametrize("text, expected", NOTES.values(), ids=NOTES.keys())
def test_the_notes_names_are_translated(text, expected):
    """A key the lecture notes use (wl, f, kd, exponent, ...) is named with rtcli's word for it."""
    assert error_of(text) == expected


# --- a misspelt key comes before the required key it stands for ---
MISSPELT_REQUIRED = {
    #            "  - triangle: {vertexes: ...": 'vertexes' at 16
    "vertexes": (obj("triangle: {vertexes: [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}"),
                 "scene.yaml:3:16: objects[0].triangle.vertexes: unknown key (did you mean 'vertices'?); "
                 "allowed here: vertices, normals"),
    "pos": (CAM + "lights:\n  - pos: [1, 2, 3]\n",
            "scene.yaml:3:5: lights[0].pos: unknown key (did you mean 'position'?); "
            "allowed here: position, color, attenuation, spot, area"),
    "camra": ("camra: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n",
              f"scene.yaml:1:1: camra: unknown key (did you mean 'camera'?); allowed here: {TOP_KEYS}"),
}


@pytest.mark.parametrize("text, expected", MISSPELT_REQUIRED.values(), ids=MISSPELT_REQUIRED.keys())
def test_a_misspelt_key_is_reported_before_the_missing_required_key(text, expected):
    assert error_of(text) == expected


# --- camera forms ---
CAMERA_FORMS = {
    "focal_without_window": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], focal: 2}\n",
                             "scene.yaml:1:46: camera.focal: the fov form of the camera takes no focal "
                             "(it takes eye, look_at, up, fov; docs/scene-format.md, Camera)"),
    "fov_with_window": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 30, "
                        "window: {left: -1, right: 1, top: 1, bottom: -1}}\n",
                        "scene.yaml:1:46: camera.fov: the window form of the camera takes no fov "
                        "(it takes eye, look_at, up, focal, window; docs/scene-format.md, Camera)"),
    "look_at_with_screen": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], "
                            "screen: {lower_left: [-2, -1, 0], horizontal: [4, 0, 0], vertical: [0, 2, 0]}}\n",
                            "scene.yaml:1:26: camera.look_at: the screen form of the camera takes no look_at "
                            "(it takes eye, screen; docs/scene-format.md, Camera)"),
}


@pytest.mark.parametrize("text, expected", CAMERA_FORMS.values(), ids=CAMERA_FORMS.keys())
def test_a_key_of_another_camera_form_says_so(text, expected):
    assert error_of(text) == expected


# --- a color YAML read as a comment ---
COMMENTED_COLORS = {
    #            "background: #ff8000": the empty value at 12
    "background": (CAM + "background: #ff8000\n",
                   'scene.yaml:2:12: background: must be a color [r, g, b] or "#rrggbb", got nothing '
                   '(YAML reads the unquoted #ff8000 as a comment: write it in quotes, "#ff8000")'),
    "material": (CAM + "materials:\n  red:\n    diffuse: #ff0000\n",
                 'scene.yaml:4:13: materials.red.diffuse: must be a color [r, g, b] or "#rrggbb", got nothing '
                 '(YAML reads the unquoted #ff0000 as a comment: write it in quotes, "#ff0000")'),
    "list_item": (CAM + "objects:\n  - sphere: {}\n    material:\n      texture:\n        checker:\n"
                  "          colors:\n            - #ff0000\n            - #00ff00\n",
                  "scene.yaml:8:14: objects[0].material.texture.checker.colors[0]: must be a color [r, g, b] or "
                  '"#rrggbb", got nothing (YAML reads the unquoted #ff0000 as a comment: write it in quotes, '
                  '"#ff0000")'),
    "flow_list": (CAM + "objects:\n  - sphere: {}\n    material: {texture: {checker: {colors: [#ff0000, #00ff00]}}}\n",
                  "scene.yaml:5:1: invalid YAML: did not find expected node content (YAML reads the unquoted "
                  '#ff0000 as a comment: write it in quotes, "#ff0000")'),
    "empty": (CAM + "background:\n",
              'scene.yaml:2:12: background: must be a color [r, g, b] or "#rrggbb", got nothing'),
}


@pytest.mark.parametrize("text, expected", COMMENTED_COLORS.values(), ids=COMMENTED_COLORS.keys())
def test_an_unquoted_hex_color_is_named(text, expected):
    """`diffuse: #ff0000` is an empty value and a YAML comment: the message says so."""
    assert error_of(text) == expected


def test_a_comment_after_a_shape_key_is_still_an_empty_shape():
    assert scene_from_yaml(obj("sphere:   # the unit sphere")).objects[0].kind == "sphere"


# --- wrong types ---
WRONG_TYPE = {
    #          "  - sphere: {radius: big}": value at 22
    "string_for_number": (obj("sphere: {radius: big}"),
                          "scene.yaml:3:22: objects[0].sphere.radius: must be a number, got 'big'"),
    "bool_for_number": (obj("sphere: {radius: true}"),
                        "scene.yaml:3:22: objects[0].sphere.radius: must be a number, got true"),
    #          "camera: {eye: [0, 5], ...": '[' at 15
    "vector2_for_vector3": ("camera: {eye: [0, 5], look_at: [0, 0, 0]}\n",
                            "scene.yaml:1:15: camera.eye: must be a vector [x, y, z] of 3 numbers, "
                            "got a list of 2"),
    #          "camera: {eye: [0, x, 5], ...": 'x' at 19
    "string_in_vector": ("camera: {eye: [0, x, 5], look_at: [0, 0, 0]}\n",
                         "scene.yaml:1:19: camera.eye[1]: must be a finite number, got 'x'"),
    #          "objects: {sphere: {}}": '{' at 10
    "mapping_for_list": (CAM + "objects: {sphere: {}}\n",
                         "scene.yaml:2:10: objects: must be a list, got a mapping"),
    "list_for_mapping": ("camera: [0, 0, 5]\n",
                         "scene.yaml:1:9: camera: must be a mapping of keys, got a list of 3"),
}


@pytest.mark.parametrize("text, expected", WRONG_TYPE.values(), ids=WRONG_TYPE.keys())
def test_wrong_type(text, expected):
    """A value of the wrong type is reported at the value, saying what was expected and what came."""
    assert error_of(text) == expected


# --- missing required keys ---
MISSING = {
    "camera": ("objects: []\n", "scene.yaml:1:1: camera: missing required key"),
    #          "camera: {look_at: ...}": the mapping starts at 9
    "eye": ("camera: {look_at: [0, 0, 0]}\n", "scene.yaml:1:9: camera.eye: missing required key"),
    "light_position": (CAM + "lights:\n  - color: [1, 1, 1]\n",
                       "scene.yaml:3:5: lights[0].position: missing required key"),
    #          "  - triangle: {}": '{' at 15
    "triangle_vertices": (obj("triangle: {}"),
                          "scene.yaml:3:15: objects[0].triangle.vertices: missing required key"),
}


@pytest.mark.parametrize("text, expected", MISSING.values(), ids=MISSING.keys())
def test_missing_required_key(text, expected):
    """A missing required key is reported at the mapping that lacks it."""
    assert error_of(text) == expected


# --- numbers out of range ---
BAD_NUMBER = {
    "inf": (obj("sphere: {radius: .inf}"),
            "scene.yaml:3:22: objects[0].sphere.radius: must be a finite number between -1e20 and 1e20, got inf"),
    "nan": (obj("sphere: {radius: .nan}"),
            "scene.yaml:3:22: objects[0].sphere.radius: must be a finite number between -1e20 and 1e20, got nan"),
    #          "  - sphere: {center: [0, .nan, 0]}": '.nan' at 26
    "nan_in_vector": (obj("sphere: {center: [0, .nan, 0]}"),
                      "scene.yaml:3:26: objects[0].sphere.center[1]: must be a finite number between -1e20 and 1e20, got nan"),
    "radius_0": (obj("sphere: {radius: 0}"),
                 "scene.yaml:3:22: objects[0].sphere.radius: must be > 0, got 0"),
    "radius_negative": (obj("sphere: {radius: -1}"),
                        "scene.yaml:3:22: objects[0].sphere.radius: must be > 0, got -1"),
    #          "image: {width: 0, height: 10}": value at 16
    "width_0": (CAM + "image: {width: 0, height: 10}\n",
                "scene.yaml:2:16: image.width: must be in 1..32768, got 0"),
    "width_40000": (CAM + "image: {width: 40000, height: 10}\n",
                    "scene.yaml:2:16: image.width: must be in 1..32768, got 40000"),
    #          "background: [0.5, -0.1, 0]": '-0.1' at 19
    "negative_color": (CAM + "background: [0.5, -0.1, 0]\n",
                       "scene.yaml:2:19: background[1]: must be a finite number >= 0, got -0.1"),
    #          'background: "#zzzzzz"': value at 13
    "bad_hex": (CAM + 'background: "#zzzzzz"\n',
                'scene.yaml:2:13: background: must be a color [r, g, b] or "#rrggbb", got \'#zzzzzz\''),
    #          "    attenuation: [0, 0, 0]": '[' at 18
    "attenuation_zero": (CAM + "lights:\n  - position: [1, 2, 3]\n    attenuation: [0, 0, 0]\n",
                         "scene.yaml:4:18: lights[0].attenuation: c0, c1, c2 must be >= 0 and not all 0"),
    "version_2": ("version: 2\n" + CAM,
                  "scene.yaml:1:10: version: unsupported version 2 (this is version 1)"),
}


@pytest.mark.parametrize("text, expected", BAD_NUMBER.values(), ids=BAD_NUMBER.keys())
def test_bad_value(text, expected):
    """A non-finite, out-of-range or malformed value is reported at the value."""
    assert error_of(text) == expected


# --- geometry ---
GEOMETRY = {
    #          "  - triangle: {vertices: [[...": '[' at 26
    "collinear_triangle": (obj("triangle: {vertices: [[0, 0, 0], [1, 1, 1], [2, 2, 2]]}"),
                           "scene.yaml:3:26: objects[0].triangle.vertices: "
                           "degenerate triangle (its vertices are collinear)"),
    #          "  - polygon: {vertices: [[...": '[' at 25
    "collinear_polygon": (obj("polygon: {vertices: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]}"),
                          "scene.yaml:3:25: objects[0].polygon.vertices: "
                          "degenerate polygon (its vertices lie on one line)"),
    "non_coplanar_polygon": (obj("polygon: {vertices: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]]}"),
                             "scene.yaml:3:25: objects[0].polygon.vertices: "
                             "polygon vertices are not coplanar"),
    #          "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], up: [0, 0, 1]}": up's '[' at 50
    "up_parallel": ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], up: [0, 0, 1]}\n",
                    "scene.yaml:1:50: camera.up: must not be parallel to the view direction (look_at - eye)"),
    #          "camera: {eye: [0, 5, 0], ...": the camera mapping at 9, up left to its default
    "default_up_parallel": ("camera: {eye: [0, 5, 0], look_at: [0, 0, 0]}\n",
                            "scene.yaml:1:9: camera: the default up [0, 1, 0] is parallel to the view "
                            "direction; give camera.up"),
    #          "      - scale: 0": value at 16
    "scale_0": (obj("sphere: {}\n    transform:\n      - scale: 0"),
                "scene.yaml:5:16: objects[0].transform[0].scale: singular transform (determinant 0)"),
    "scale_vector_with_0": (obj("sphere: {}\n    transform:\n      - scale: [1, 0, 1]"),
                            "scene.yaml:5:16: objects[0].transform[0].scale: "
                            "singular transform (determinant 0)"),
    #          "      - matrix: [[": '[' at 17
    "singular_matrix": (obj("sphere: {}\n    transform:\n"
                            "      - matrix: [[1, 0, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0]]"),
                        "scene.yaml:5:17: objects[0].transform[0].matrix: singular transform (determinant 0)"),
}


@pytest.mark.parametrize("text, expected", GEOMETRY.values(), ids=GEOMETRY.keys())
def test_degenerate_geometry(text, expected):
    """Degenerate shapes, cameras and transforms are reported at the offending value."""
    assert error_of(text) == expected


# --- references and object structure ---
REFERENCES = {
    #          "materials:\n  m: {preset: brasss}": value at 15
    "unknown_preset": (CAM + "materials:\n  m: {preset: brasss}\n",
                       "scene.yaml:3:15: materials.m.preset: unknown preset 'brasss' "
                       "(did you mean 'brass'? `rtcli presets` lists them)"),
    "unknown_preset_far_off": (CAM + "materials:\n  m: {preset: velvet}\n",
                               "scene.yaml:3:15: materials.m.preset: unknown preset 'velvet' "
                               "(`rtcli presets` lists them)"),
    #          "    material: nope": value at 15
    "unknown_material": (obj("sphere: {}\n    material: nope"),
                         "scene.yaml:4:15: objects[0].material: unknown material 'nope' "
                         "(the scene defines no materials)"),
    "misspelt_material": (CAM + "materials:\n  red: {diffuse: [1, 0, 0]}\nobjects:\n"
                          "  - sphere: {}\n    material: rde\n",
                          "scene.yaml:6:15: objects[0].material: unknown material 'rde' (did you mean 'red'?)"),
    "other_material": (CAM + "materials:\n  red: {diffuse: [1, 0, 0]}\n  blue: {diffuse: [0, 0, 1]}\n"
                       "objects:\n  - sphere: {}\n    material: green\n",
                       "scene.yaml:7:15: objects[0].material: unknown material 'green' (defined: red, blue)"),
    "preset_as_material": (obj("sphere: {}\n    material: copper"),
                           "scene.yaml:4:15: objects[0].material: unknown material 'copper' "
                           "(copper is a preset: write material: {preset: copper})"),
    "two_shapes": (obj("sphere: {}\n    box: {}"),
                   "scene.yaml:4:5: objects[0].box: an object has one shape, but 'sphere' is already given"),
    "no_shape": (obj("name: x"),
                 "scene.yaml:3:5: objects[0]: missing shape: one of " + ", ".join([*SHAPES, "csg", "group"])),
}


@pytest.mark.parametrize("text, expected", REFERENCES.values(), ids=REFERENCES.keys())
def test_bad_reference_or_structure(text, expected):
    """Unknown names and objects without exactly one shape are reported where they are written."""
    assert error_of(text) == expected


def test_missing_texture_image(tmp_path):
    """A texture image that does not exist is reported at its file name, with the resolved path."""
    text = CAM + "materials:\n  m:\n    texture: {image: nope.png}\n"
    #                                              'nope.png' at 22 of line 4
    assert error_of(text, tmp_path) == (f"{tmp_path}/scene.yaml:4:22: materials.m.texture.image: "
                                        f"file not found: {tmp_path}/nope.png (looked for in {tmp_path}: a relative "
                                        "name starts from the folder of the file it is written in)")


# --- what loads: cameras ---
def test_fov_camera_loads():
    """The field-of-view form loads, with fov and up defaults filled in."""
    s = scene_from_yaml("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 30}\n")
    assert s.camera.func is cameras.from_fov
    assert s.camera.args[3] == 30.0 and np.array_equal(s.camera.args[2], [0, 1, 0])
    assert np.array_equal(s.camera(4, 3).eye, [0, 0, 5])
    assert np.array_equal(s.eye, [0, 0, 5])


def test_window_camera_loads():
    """The window form loads, with focal and window edges as written."""
    s = scene_from_yaml("camera: {eye: [0, 0, 5], look_at: [0, 0, 0], up: [0, 1, 0], focal: 2,\n"
                        "         window: {left: -1, right: 1, top: 0.75, bottom: -0.75}}\n")
    assert s.camera.func is cameras.from_window
    assert s.camera.args[3:] == (2.0, -1.0, 1.0, 0.75, -0.75)
    assert np.array_equal(s.camera(4, 3).eye, [0, 0, 5])


def test_screen_camera_loads():
    """The screen form loads: pixel (0, 0)'s top-left corner is lower_left + vertical."""
    s = scene_from_yaml("camera:\n  eye: [0, 0, 5]\n"
                        "  screen: {lower_left: [-2, -1, 0], horizontal: [4, 0, 0], vertical: [0, 2, 0]}\n")
    assert s.camera.func is cameras.from_screen
    cam = s.camera(4, 2)
    assert np.allclose(cam.origin, [-2, 1, 0])
    assert np.allclose(cam.right, [4, 0, 0]) and np.allclose(cam.down, [0, -2, 0])


# --- what loads: materials ---
BRASS = dict(ambient=[0.329412, 0.223529, 0.027451], diffuse=[0.780392, 0.568627, 0.113725],
             specular=[0.992157, 0.941176, 0.807843], shininess=27.8974)
COPPER = dict(ambient=[0.19125, 0.0735, 0.0225], diffuse=[0.7038, 0.27048, 0.0828],
              specular=[0.256777, 0.137622, 0.086014], shininess=12.8)


def assert_preset(m, numbers):
    for key, value in numbers.items():
        assert np.array_equal(getattr(m, key), value), key


def test_preset_brass_gives_the_published_numbers():
    """`preset: brass` gives McReynolds/Blythe's brass numbers and no mirror or transparency."""
    m = material_of(scene_from_yaml(obj("sphere: {}\n    material: {preset: brass}")))
    assert_preset(m, BRASS)
    assert not m.reflection.any() and not m.transmission.any()


def test_preset_then_overrides():
    """`{preset: copper, reflection: 0.3}` keeps copper's numbers and adds the override on top."""
    s = scene_from_yaml(CAM + "materials:\n  shiny_copper: {preset: copper, reflection: 0.3, shininess: 40}\n"
                        "objects:\n  - sphere: {}\n    material: shiny_copper\n")
    m = material_of(s)
    assert_preset(m, dict(COPPER, shininess=40.0))
    assert np.array_equal(m.reflection, [0.3, 0.3, 0.3])


def test_coefficient_single_number_means_three_equal_channels():
    """A coefficient written as one number k means [k, k, k]."""
    m = material_of(scene_from_yaml(obj("sphere: {}\n    material: {diffuse: 0.5, specular: 0.25, ambient: 0.1}")))
    assert np.array_equal(m.diffuse, [0.5] * 3)
    assert np.array_equal(m.specular, [0.25] * 3)
    assert np.array_equal(m.ambient, [0.1] * 3)


def test_hex_colors():
    """"#ff8000" is [1, 128/255, 0], as a color and as a coefficient."""
    s = scene_from_yaml(CAM + 'background: "#ff8000"\nobjects:\n  - sphere: {}\n'
                        '    material: {diffuse: "#FF8000"}\n')
    assert np.allclose(s.background, [1.0, 128 / 255, 0.0])
    assert np.allclose(material_of(s).diffuse, [1.0, 128 / 255, 0.0])


def test_named_and_inline_materials():
    """An object's material is a name from `materials` or an inline mapping; names can be shared."""
    s = scene_from_yaml(CAM + "materials:\n  red: {diffuse: [1, 0, 0]}\nobjects:\n"
                        "  - sphere: {}\n    material: red\n"
                        "  - sphere: {}\n    material: {diffuse: [0, 0, 1]}\n"
                        "  - sphere: {}\n    material: red\n")
    assert np.array_equal(material_of(s, 0).diffuse, [1, 0, 0])
    assert np.array_equal(material_of(s, 1).diffuse, [0, 0, 1])
    assert s.objects[0].material == s.objects[2].material != s.objects[1].material


def test_default_material_is_white_diffuse():
    """An object without `material:` gets a white (grey-equal) diffuse material with no specular or mirror."""
    m = material_of(scene_from_yaml(obj("sphere: {}")))
    assert m.diffuse[0] > 0 and np.all(m.diffuse == m.diffuse[0])
    assert not m.specular.any() and not m.reflection.any() and not m.transmission.any()
    assert not m.emission.any() and m.texture is None


def test_anchors_aliases_and_merge_keys_in_materials():
    """`&shiny`/`*shiny` reuse a material mapping; `<<: *base` merges one and overrides keys."""
    s = scene_from_yaml(CAM + "materials:\n"
                        "  base: &base {diffuse: 0.5, specular: 0.9, shininess: 64}\n"
                        "  derived: {<<: *base, specular: 0.1}\n"
                        "objects:\n"
                        "  - sphere: {}\n    material: &shiny {diffuse: 0.2, reflection: 0.7}\n"
                        "  - sphere: {}\n    material: *shiny\n"
                        "  - sphere: {}\n    material: derived\n")
    for k in (0, 1):
        assert np.array_equal(material_of(s, k).diffuse, [0.2] * 3)
        assert np.array_equal(material_of(s, k).reflection, [0.7] * 3)
    d = material_of(s, 2)
    assert np.array_equal(d.diffuse, [0.5] * 3) and np.array_equal(d.specular, [0.1] * 3)
    assert d.shininess == 64.0


def test_exponent_without_dot_in_a_scene():
    """`1e-6` in a scene is a number (here the render epsilon), not a string."""
    s = scene_from_yaml(CAM + "render: {epsilon: 1e-6}\n")
    assert s.settings.epsilon == 1e-6


# --- includes ---
def test_includes_merge_first_with_paths_relative_to_the_includer(tmp_path):
    """Included materials/lights/objects come first (depth first); nested includes resolve from their own folder."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "common.yaml").write_text(
        "include: [deeper.yaml]\n"                      # sub/deeper.yaml, relative to sub/
        "materials:\n  gold_m: {preset: gold}\n"
        "lights:\n  - position: [0, 0, 2]\n"
        "objects:\n  - name: common_ball\n    sphere: {}\n    material: red\n")
    (tmp_path / "sub" / "deeper.yaml").write_text(
        "materials:\n  red: {diffuse: [1, 0, 0]}\n"
        "lights:\n  - position: [0, 0, 1]\n"
        "objects:\n  - name: deep_ball\n    sphere: {}\n")
    s = scene_from_yaml("include: [sub/common.yaml]\n" + CAM +
                        "lights:\n  - position: [0, 0, 3]\n"
                        "objects:\n  - name: main_ball\n    sphere: {}\n    material: gold_m\n", tmp_path)
    assert [(o.id, o.name) for o in s.objects] == [(1, "deep_ball"), (2, "common_ball"), (3, "main_ball")]
    assert [light.position[2] for light in s.lights] == [1, 2, 3]
    assert np.array_equal(material_of(s, 1).diffuse, [1, 0, 0])
    assert np.array_equal(material_of(s, 2).diffuse, [0.75164, 0.60648, 0.22648])


# --- groups and transforms ---
def T(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def S(x, y, z):
    return np.diag([x, y, z, 1.0])


RZ90 = np.array([[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])   # +90 degrees about z


def test_transforms_compose_in_the_order_listed():
    """scale, then rotate, then translate: world_from_object = T R S, and m_inv is its inverse."""
    s = scene_from_yaml(obj("sphere: {}\n    transform:\n"
                            "      - scale: [1, 2, 3]\n"
                            "      - rotate: {axis: [0, 0, 1], degrees: 90}\n"
                            "      - translate: [1, 2, 3]"))
    t = s.objects[0].world_from_object
    expected = T(1, 2, 3) @ RZ90 @ S(1, 2, 3)
    assert np.allclose(t.m, expected, atol=1e-12)
    assert np.allclose(t.m_inv, np.linalg.inv(expected), atol=1e-12)


def test_uniform_scale_number():
    """`scale: 2` scales all three axes."""
    t = scene_from_yaml(obj("sphere: {}\n    transform: [{scale: 2}]")).objects[0].world_from_object
    assert np.array_equal(t.m, S(2, 2, 2))


def test_matrix_with_3_rows():
    """`matrix:` with 3 rows of 4 numbers is the top of an affine 4x4, rows as written."""
    t = scene_from_yaml(obj("sphere: {}\n    transform:\n"
                            "      - matrix: [[1, 0, 0, 4], [0, 2, 0, 5], [0, 0, 3, 6]]")).objects[0].world_from_object
    assert np.array_equal(t.m, [[1, 0, 0, 4], [0, 2, 0, 5], [0, 0, 3, 6], [0, 0, 0, 1]])


def test_matrix_with_4_rows():
    """`matrix:` with 4 rows (the last [0, 0, 0, 1]) is taken as written."""
    t = scene_from_yaml(obj("sphere: {}\n    transform:\n"
                            "      - matrix: [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]")
                        ).objects[0].world_from_object
    assert np.array_equal(t.m, T(1, 2, 3) @ RZ90)


def test_group_ids_depth_first_and_transform_after_the_childs():
    """Group children get ids depth first; each child's own transform applies first, then the group's."""
    s = scene_from_yaml(CAM + "objects:\n"
                        "  - name: first\n    sphere: {}\n"
                        "  - group:\n"
                        "      objects:\n"
                        "        - name: a\n          sphere: {}\n          transform: [{scale: 2}]\n"
                        "        - group:\n"
                        "            objects:\n"
                        "              - name: b\n                box: {}\n"
                        "          transform: [{rotate: {axis: [0, 0, 1], degrees: 90}}]\n"
                        "        - name: c\n          sphere: {}\n"
                        "    transform: [{translate: [1, 0, 0]}]\n"
                        "    material: {diffuse: [0, 1, 0]}\n"
                        "  - name: last\n    sphere: {}\n")
    assert [(o.id, o.name) for o in s.objects] == [(1, "first"), (2, "a"), (3, "b"), (4, "c"), (5, "last")]
    by = {o.name: o for o in s.objects}
    assert np.allclose(by["a"].world_from_object.m, T(1, 0, 0) @ S(2, 2, 2))
    assert np.allclose(by["b"].world_from_object.m, T(1, 0, 0) @ RZ90, atol=1e-12)
    assert np.allclose(by["c"].world_from_object.m, T(1, 0, 0))
    assert by["first"].world_from_object is None and by["last"].world_from_object is None
    assert np.array_equal(material_of(s, 3).diffuse, [0, 1, 0])       # c inherits the group's material
