"""Hostile and extreme scene files: every one gets one located line, in bounded time and memory.

Loading that cannot explode (aliases, merge keys, includes, special files, size
limits, decompression bombs), numbers at the edges, and messages that stay on
one line whatever the scene says.
"""

from __future__ import annotations

import os
import time
import tracemalloc

import pytest
from PIL import Image

from rtcli.errors import SceneError
from rtcli.scenefile import guards, yamlfile
from rtcli.scenefile.load import scene_from_docs

CAM = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: 6}\n"


def load_error(tmp_path, text: str, name: str = "scene.yaml") -> str:
    """The one-line message of loading `text` as tmp_path/name."""
    (tmp_path / name).write_text(text)
    with pytest.raises(SceneError) as e:
        scene_from_docs(yamlfile.load(str(tmp_path / name)))
    message = str(e.value)
    assert "\n" not in message and "\r" not in message
    return message.replace(str(tmp_path) + "/", "")


def tens(prefix: str, levels: int, leaf: str, wrap: str) -> str:
    """Anchors prefix0 .. prefixN, each holding ten aliases of the one before: 10^N copies."""
    lines = [f"  - &{prefix}0 {leaf}"]
    for i in range(1, levels + 1):
        refs = ", ".join([f"*{prefix}{i - 1}"] * 10)
        lines.append("  - &%s%d %s" % (prefix, i, wrap.replace("REFS", refs)))
    return "\n".join(lines) + "\n"


# --- aliases, merge keys, recursion, nesting ---
def test_alias_bomb_is_refused_quickly_at_the_alias(tmp_path):
    """A billion spheres through nine levels of ten aliases: refused at the alias that crosses the budget."""
    text = CAM + "objects:\n" + tens("g", 9, "{sphere: {}}", "{group: {objects: [REFS]}}")
    start = time.monotonic()
    message = load_error(tmp_path, text)
    assert time.monotonic() - start < 10
    assert message.startswith("scene.yaml:10:43: ")
    assert message.endswith("aliases repeat more than 1,000,000 values (each alias counts as a copy of what it names)")


def test_list_alias_bomb_in_memory_bounds(tmp_path):
    """Nested lists of aliases (a 'billion laughs') are refused with little memory."""
    text = CAM + "x:\n" + tens("a", 9, "[1, 2, 3]", "[REFS]") + "objects: []\n"
    tracemalloc.start()
    try:
        load_error(tmp_path, text)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6


def test_merge_keys_that_double_each_level_stay_small(tmp_path):
    """Sixty levels of `<<: [*prev, *prev]` (2^60 entries if copied naively) load at once."""
    lines = ["m0: &m0 {diffuse: 0.5, specular: 0.2}"]
    lines += [f"m{i}: &m{i} {{<<: [*m{i - 1}, *m{i - 1}], shininess: {i}}}" for i in range(1, 60)]
    tree = yamlfile.parse("\n".join(lines) + "\n", "s.yaml")
    assert tree["m59"] == {"diffuse": 0.5, "specular": 0.2, "shininess": 59}


def test_merge_order_and_locations_follow_pyyaml():
    """The first mapping listed in `<<: [...]` wins over later ones; written keys win over all."""
    text = "a: &a {x: 1, y: 1}\nb: &b {x: 2, z: 2}\nc: {<<: [*a, *b], z: 3}\n"
    tree = yamlfile.parse(text, "s.yaml")
    assert tree["c"] == {"x": 1, "z": 3, "y": 1}
    assert str(tree["c"].value_where["z"]) == "s.yaml:3:22"
    assert str(tree["c"].key_where["y"]) == "s.yaml:1:14"


def test_recursive_alias_is_refused(tmp_path):
    message = load_error(tmp_path, CAM + "objects: &o [{group: {objects: *o}}]\n")
    assert message == ("scene.yaml:3:32: alias *o names a collection that contains it "
                       "(recursive values are not allowed)")


@pytest.mark.parametrize("depth", [300, 20000])
def test_deep_nesting_is_one_line(tmp_path, depth):
    message = load_error(tmp_path, CAM + "objects: " + "[" * depth + "]" * depth + "\n")
    assert message.startswith("scene.yaml:3:")


def test_object_count_is_capped(tmp_path, monkeypatch):
    monkeypatch.setattr(guards, "MAX_OBJECTS", 3)
    message = load_error(tmp_path, CAM + "objects: [{sphere: {}}, {sphere: {}}, {sphere: {}}, {sphere: {}}]\n")
    assert message == "scene.yaml:3:53: objects[3]: too many objects: a scene holds at most 3"


# --- includes ---
def test_diamond_includes_load_each_file_once(tmp_path):
    """30 levels of two files that both include the next two: 2^30 paths, 60 files, each read once."""
    for i in range(30):
        nxt = f"[d{i + 1}a.yaml, d{i + 1}b.yaml]" if i < 29 else "[]"
        for side in "ab":
            (tmp_path / f"d{i}{side}.yaml").write_text(f"include: {nxt}\nobjects: [{{sphere: {{}}}}]\n")
    (tmp_path / "scene.yaml").write_text(CAM + "include: [d0a.yaml, d0b.yaml]\n")
    start = time.monotonic()
    docs = yamlfile.load(str(tmp_path / "scene.yaml"))
    assert time.monotonic() - start < 10
    assert len(docs) == 61 and len(scene_from_docs(docs).objects) == 60


def test_include_depth_is_limited(tmp_path):
    for i in range(40):
        (tmp_path / f"i{i}.yaml").write_text(f"include: [i{i + 1}.yaml]\n" if i < 39 else "objects: []\n")
    message = load_error(tmp_path, CAM + "include: [i0.yaml]\n")
    assert message == "i31.yaml:1:11: include[0]: includes nest more than 32 deep"


# --- files that are not regular files, or too large ---
@pytest.fixture
def specials(tmp_path):
    """Paths of a FIFO, a folder and two character devices."""
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "folder").mkdir()
    return {"fifo": (str(tmp_path / "fifo"), "a FIFO (named pipe)"),
            "folder": (str(tmp_path / "folder"), "a folder"),
            "zero": ("/dev/zero", "a character device"),
            "urandom": ("/dev/urandom", "a character device")}


@pytest.mark.parametrize("which", ["fifo", "folder", "zero", "urandom"])
@pytest.mark.parametrize("use", ["scene", "include", "mesh", "texture"])
def test_special_files_are_refused_before_opening(tmp_path, specials, which, use):
    """Opening a FIFO would block and /dev/zero never ends: both are refused from os.stat."""
    path, kind = specials[which]
    text = {"scene": None,
            "include": CAM + f"include: ['{path}']\n",
            "mesh": CAM + f"objects: [{{mesh: {{file: '{path}'}}}}]\n",
            "texture": CAM + f"objects: [{{sphere: {{}}, material: {{texture: {{image: '{path}'}}}}}}]\n"}[use]
    start = time.monotonic()
    with pytest.raises(SceneError) as e:
        if text is None:
            yamlfile.load(path)
        else:
            (tmp_path / "scene.yaml").write_text(text)
            scene_from_docs(yamlfile.load(str(tmp_path / "scene.yaml")))
    assert time.monotonic() - start < 5
    assert str(e.value).endswith(f"not a regular file but {kind}")


def test_a_scene_larger_than_the_limit_is_refused_unread(tmp_path):
    big = tmp_path / "big.yaml"
    with open(big, "wb") as f:
        f.truncate(100 * 1024 * 1024)                    # sparse: costs no disk, reading it would cost 100 MB
    tracemalloc.start()
    try:
        with pytest.raises(SceneError) as e:
            yamlfile.load(str(big))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert str(e.value).endswith("too large: 100.0 MB, more than the 64 MB allowed")
    assert peak < 1e6


def test_decompression_bomb_texture_is_a_located_error(tmp_path):
    Image.new("1", (12000, 12000)).save(tmp_path / "bomb.png")       # 144 million texels in a few kB
    text = CAM + "objects: [{sphere: {}, material: {texture: {image: bomb.png}}}]\n"
    message = load_error(tmp_path, text)
    assert message.startswith("scene.yaml:3:52: objects[0].material.texture.image: cannot read image ")
    assert "decompression bomb" in message


# --- YAML text ---
@pytest.mark.parametrize("char, column", [("\0", 7), ("\x07", 7), ("\x1b", 7)])
def test_control_characters_are_located(tmp_path, char, column):
    message = load_error(tmp_path, CAM + f"x: \"ab{char}c\"\n")
    assert message == (f"scene.yaml:3:{column}: invalid YAML: the character U+{ord(char):04X} is not "
                       "allowed (control characters cannot appear in YAML)")


def test_control_character_after_non_ascii_text_is_located(tmp_path):
    """libyaml counts bytes; the column is still in characters."""
    message = load_error(tmp_path, CAM + "x: \"ééé\0\"\n")
    assert message.startswith("scene.yaml:3:8: ")


def test_bytes_that_are_not_utf8_are_located(tmp_path):
    (tmp_path / "scene.yaml").write_bytes(CAM.encode() + b"x: caf\xe9\n")
    with pytest.raises(SceneError) as e:
        yamlfile.load(str(tmp_path / "scene.yaml"))
    assert str(e.value).endswith("scene.yaml:3:7: not UTF-8 text (byte 0xe9)")


@pytest.mark.parametrize("text, expected", [
    ("objects: !!set {a}\n", "scene.yaml:3:10: invalid YAML: unsupported tag 'tag:yaml.org,2002:set'"),
    ("objects: [{sphere: {radius: !!int abc}}]\n", "scene.yaml:3:29: invalid YAML: 'abc' is not a valid !!int"),
    ("? [a, b]\n: 1\n", "scene.yaml:3:3: keys must be plain names"),
    ("objects: *nope\n", "scene.yaml:3:10: invalid YAML: undefined alias *nope"),
    ("a: &x 1\nb: &x 2\n", "scene.yaml:4:4: duplicate anchor &x (first given at line 3)"),
    ("a: {<<: 1}\n", "scene.yaml:3:9: invalid YAML: a merge key (<<) takes a mapping or a list of mappings"),
    ("objects: []\n---\nx: 1\n", "scene.yaml:4:1: invalid YAML: a scene is a single document (found a second one)"),
])
def test_odd_yaml_is_one_located_line(tmp_path, text, expected):
    assert load_error(tmp_path, CAM + text) == expected


# --- numbers at the edges ---
@pytest.mark.parametrize("objects, expected", [
    ("[{sphere: {radius: 1e300}}]", "objects[0].sphere.radius: must be between -1e20 and 1e20, got 1e+300"),
    ("[{triangle: {vertices: [[0, 0, 0], [1e300, 0, 0], [0, 1e300, 0]]}}]",
     "objects[0].triangle.vertices[1][0]: must be between -1e20 and 1e20, got 1e+300"),
    ("[{sphere: {}, transform: [{scale: 1e200}]}]",
     "objects[0].transform[0].scale: must be between -1e20 and 1e20, got 1e+200"),
    ("[{sphere: {}, transform: [{matrix: [[1e200, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}]}]",
     "objects[0].transform[0].matrix[0][0]: must be between -1e20 and 1e20, got 1e+200"),
    ("[{sphere: {}, transform: [{scale: 1e15}, {scale: 1e15}]}]",
     "objects[0].transform: the composed transform is too large: its entries must be between -1e20 and 1e20"),
    ("[{sphere: {}, transform: [{scale: 1e-200}]}]",
     "objects[0].transform[0].scale: a scale factor must be 0 or at least 1e-20 in magnitude, got 1e-200"),
    ("[{sphere: {radius: " + "9" * 400 + "}}]",
     "objects[0].sphere.radius: must be between -1e20 and 1e20, got an integer of 400 digits"),
    ("[{sphere: {radius: 0x" + "f" * 5000 + "}}]",
     "objects[0].sphere.radius: must be between -1e20 and 1e20, got an integer of 6021 digits"),
    ("[{sphere: {}, material: {reflection: 2}}]", "objects[0].material.reflection[0]: must be at most 1, got 2"),
])
def test_out_of_range_numbers_name_the_range(tmp_path, objects, expected):
    assert load_error(tmp_path, CAM + f"objects: {objects}\n").split(": ", 1)[1] == expected


def test_integer_past_pythons_digit_limit_is_located(tmp_path):
    message = load_error(tmp_path, CAM + "objects: [{sphere: {radius: " + "9" * 5000 + "}}]\n")
    assert message == ("scene.yaml:3:29: a number of 5000 digits is out of range "
                       "(numbers must be between -1e20 and 1e20)")


def test_eye_far_away_is_refused(tmp_path):
    message = load_error(tmp_path, "camera: {eye: [0, 0, 1e300], look_at: [0, 0, 0]}\nobjects: []\n")
    assert message == "scene.yaml:1:22: camera.eye[2]: must be between -1e20 and 1e20, got 1e+300"


# --- messages stay on one line ---
@pytest.mark.parametrize("text, expected", [
    ('"fo\\no": 1\n', "scene.yaml:3:1: 'fo\\no': unknown key; allowed here: version, include, image, camera, "
                    "background, ambient, render, lights, materials, objects, animation"),
    ('objects: [{sphere: {"radiu\\ns": 1}}]\n',
     "scene.yaml:3:21: objects[0].sphere.'radiu\\ns': unknown key (did you mean 'radius'?); "
     "allowed here: center, radius"),
    ('objects: [{sphere: {}, material: "x\\nerror: forged"}]\n',
     "scene.yaml:3:34: objects[0].material: unknown material 'x\\nerror: forged' (the scene defines no materials)"),
    ('objects: [{sphere: {}, material: {preset: "\\e[31mred"}}]\n',
     "scene.yaml:3:43: objects[0].material.preset: unknown preset '\\x1b[31mred' (`rtcli presets` lists them)"),
    ('include: ["a\\nb.yaml"]\n', "scene.yaml:3:11: include[0]: file not found: 'a\\nb.yaml'"),
    ('materials: {"m\\r\\n": {diffuse: x}}\nobjects: []\n',
     "scene.yaml:3:32: materials.'m\\r\\n'.diffuse: must be a color [r, g, b] or \"#rrggbb\", got 'x'"),
])
def test_user_text_is_quoted_with_escapes(tmp_path, text, expected):
    message = load_error(tmp_path, CAM + text)
    assert message.replace(str(tmp_path) + "/", "") == expected


def test_a_file_name_with_a_newline_is_quoted(tmp_path):
    (tmp_path / "a\nb.yaml").write_text(CAM + "objects: [{sphere: {radius: -1}}]\n")
    with pytest.raises(SceneError) as e:
        scene_from_docs(yamlfile.load(str(tmp_path / "a\nb.yaml")))
    path = str(tmp_path / "a\nb.yaml")
    assert str(e.value) == f"{path!r}:3:29: objects[0].sphere.radius: must be > 0, got -1"


# --- memory of a big scene's YAML side ---
def test_yaml_side_of_a_sphere_is_small(tmp_path):
    """The tree of a 20,000-sphere scene, locations included, costs under 1.5 kB a sphere."""
    line = "- {sphere: {center: [1.234, -5.678, 9.012], radius: 0.05}, material: red}\n"
    (tmp_path / "many.yaml").write_text(CAM + "materials: {red: {diffuse: [1, 0, 0]}}\nobjects:\n" + line * 20000)
    tracemalloc.start()
    try:
        docs = yamlfile.load(str(tmp_path / "many.yaml"))
        kept, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(docs[0]["objects"]) == 20000
    assert kept / 20000 < 1500 and peak / 20000 < 2000


def test_eye_whose_image_plane_rounds_away_is_refused(tmp_path):
    """At 1e17 from the origin a plane one unit from the eye is lost in rounding: rays would have no direction."""
    message = load_error(tmp_path, "camera: {eye: [0, 0, 1e17], look_at: [0, 0, 0]}\nobjects: []\n")
    assert message.startswith("scene.yaml:1:9: camera: the eye is too far from the origin for the size of its "
                              "image plane")
