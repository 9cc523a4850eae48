"""Tests for rtcli.scenefile.yamlfile: located YAML loading, anchors, merge keys, includes.

Columns in comments are 1-based and were counted by hand.
"""

from __future__ import annotations

import os

import pytest
import yaml
from helpers import scene_from_yaml

from rtcli.errors import SceneError
from rtcli.scenefile import yamlfile

CAM = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
LIBYAML = hasattr(yaml, "CSafeLoader")       # yamlfile uses libyaml's parser when present


def parse_error(text: str) -> str:
    """The one-line message of parsing `text` as scene.yaml."""
    with pytest.raises(SceneError) as e:
        yamlfile.parse(text, "scene.yaml")
    return str(e.value)


def build_error(text: str) -> str:
    """The one-line message of building a scene from `text` (shown as scene.yaml)."""
    with pytest.raises(SceneError) as e:
        scene_from_yaml(text)
    return str(e.value)


# --- syntax errors ---
def test_unclosed_bracket_points_at_the_offending_brace():
    """An unclosed '[' is reported where the parser finds '}' instead of ',' or ']'."""
    text = "camera: {eye: [0, 0, 5], look_at: [0, 0, 0}\nobjects: []\n"
    #        '}' is column 43 of line 1
    problem = "did not find expected ',' or ']'" if LIBYAML else "expected ',' or ']', but got '}'"
    assert parse_error(text) == f"scene.yaml:1:43: invalid YAML: {problem}"


def test_unclosed_bracket_at_end_of_file_is_located():
    """A '[' never closed is reported at the end of the file (line 3, column 1)."""
    text = "objects: [\n  {sphere: {}}\n"
    assert parse_error(text).startswith("scene.yaml:3:1: invalid YAML: ")


def test_tab_indentation_is_located():
    """A tab used for indentation is reported at its own line and column."""
    text = "camera:\n\teye: [0, 0, 5]\n"
    assert parse_error(text) == "scene.yaml:2:1: invalid YAML: tab characters cannot indent YAML (use spaces)"


def test_top_level_list_is_an_error():
    """A top level that is a list, not a mapping, is an error at 1:1."""
    assert parse_error("- sphere: {}\n- box: {}\n") == "scene.yaml:1:1: a scene must be a mapping of keys"


def test_empty_file_is_an_empty_mapping():
    """An empty document parses as an empty mapping located at 1:1."""
    tree = yamlfile.parse("", "scene.yaml")
    assert tree == {} and str(tree.where) == "scene.yaml:1:1"


# --- duplicate keys ---
def test_duplicate_top_level_key():
    """A repeated top-level key is reported at the second occurrence, naming the first."""
    text = CAM + "camera: {eye: [0, 0, 5]}\n"
    assert build_error(text) == "scene.yaml:2:1: camera: duplicate key (first given at line 1)"


def test_duplicate_nested_key_names_its_full_path():
    """A repeated key inside a shape names the full key path, at the second occurrence."""
    text = CAM + "objects:\n  - sphere: {radius: 1, radius: 2}\n"
    #                        second 'radius' is column 25 of line 3
    assert build_error(text) == "scene.yaml:3:25: objects[0].sphere.radius: duplicate key (first given at line 3)"


# --- anchors, aliases, merge keys, numbers ---
def test_anchor_and_alias_share_a_mapping():
    """`&shiny` ... `*shiny` gives the same values at both places."""
    tree = yamlfile.parse("a: &shiny {diffuse: 0.5, shininess: 64}\nb: *shiny\n", "s.yaml")
    assert tree["b"] == {"diffuse": 0.5, "shininess": 64}
    assert tree["b"] is tree["a"]


def test_merge_key_then_override():
    """`<<: *base` merges the base mapping; keys written next to it win, and are not duplicates."""
    text = "base: &base {diffuse: 0.5, specular: 0.9}\nderived: {<<: *base, specular: 0.1}\n"
    tree = yamlfile.parse(text, "s.yaml")
    assert tree["derived"] == {"diffuse": 0.5, "specular": 0.1}
    assert "<<" not in tree["derived"]


def test_exponent_without_dot_is_a_float():
    """`1e-6` (YAML 1.1 would read a string) parses as a float."""
    tree = yamlfile.parse("a: 1e-6\nb: 2E+3\nc: -3e2\nd: 1.5e-3\n", "s.yaml")
    assert tree == {"a": 1e-6, "b": 2000.0, "c": -300.0, "d": 1.5e-3}
    assert all(type(v) is float for v in tree.values())


def test_python_object_tags_are_refused():
    """Python object tags are not constructed (safe loading)."""
    msg = parse_error("a: !!python/object/apply:os.system ['true']\n")
    assert msg.startswith("scene.yaml:1:4: invalid YAML: ")


def test_nodes_remember_key_and_value_locations():
    """A mapping records where each key and each value starts; a list where each item starts."""
    tree = yamlfile.parse("objects:\n  - sphere: {radius: 2}\n", "s.yaml")
    item = tree["objects"][0]
    assert str(tree.key_where["objects"]) == "s.yaml:1:1"
    assert str(tree["objects"].item_where[0]) == "s.yaml:2:5"
    assert str(item["sphere"].value_where["radius"]) == "s.yaml:2:22"


# --- includes ---
def test_missing_include_file(tmp_path):
    """A missing include names the file, at the include list item."""
    with pytest.raises(SceneError) as e:
        scene_from_yaml(CAM + "include: [nope.yaml]\n", tmp_path)
    #                             'nope.yaml' is column 11 of line 2
    assert str(e.value) == f"{tmp_path}/scene.yaml:2:11: include[0]: file not found: {tmp_path}/nope.yaml"


def test_include_cycle(tmp_path):
    """a.yaml includes b.yaml includes a.yaml: reported at b.yaml's include item, with the chain."""
    (tmp_path / "b.yaml").write_text("include: [a.yaml]\n")
    with pytest.raises(SceneError) as e:
        scene_from_yaml("include: [b.yaml]\n" + CAM, tmp_path, name="a.yaml")
    assert str(e.value) == f"{tmp_path}/b.yaml:1:11: include[0]: include cycle: a.yaml -> b.yaml -> a.yaml"


def test_included_file_may_not_set_the_camera(tmp_path):
    """Only materials, lights and objects merge: a camera in an included file is an error there."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "c.yaml").write_text(CAM)
    with pytest.raises(SceneError) as e:
        scene_from_yaml(CAM + "include: [sub/c.yaml]\n", tmp_path)
    assert str(e.value) == (f"{tmp_path}/sub/c.yaml:1:1: camera: not allowed in an included file "
                            "(only materials, lights and objects are merged)")


def test_load_returns_included_documents_first(tmp_path):
    """load() gives the included files depth first, the main file last; paths relative to each includer."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "common.yaml").write_text("include: [deeper.yaml]\nobjects: []\n")
    (tmp_path / "sub" / "deeper.yaml").write_text("objects: []\n")
    (tmp_path / "scene.yaml").write_text("include: [sub/common.yaml]\n" + CAM)
    docs = yamlfile.load(str(tmp_path / "scene.yaml"))
    assert [d.where.file for d in docs] == [str(tmp_path / "sub" / "deeper.yaml"),
                                            str(tmp_path / "sub" / "common.yaml"),
                                            str(tmp_path / "scene.yaml")]
    assert docs[0].folder == str(tmp_path / "sub")


# --- the event-built tree reads YAML as PyYAML's safe loader does ---
class _PyYAML(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """PyYAML's own safe loader with rtcli's one extra rule (1e-6 is a float)."""


_PyYAML.add_implicit_resolver("tag:yaml.org,2002:float",
                              __import__("re").compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
                              list("-+0123456789"))

SCALARS = ["1", "-1", "+1", "0", "-0", "00", "017", "0x1F", "0b101", "1_000", "1:20", "190:20:30.15",
           "123456789012345678", "1234567890123456789012", "1.5", "-1.5", "1.", ".5", "-.5", "01.50", "1e5",
           "1E-6", "-3e2", "1.5e3", "1_0.5", ".inf", "-.Inf", ".nan", "yes", "No", "on", "OFF", "true",
           "null", "~", "", "2001-12-14", "2001-12-14t21:59:43.10-05:00", "abc", "'1'", '"2.5"', "!!str 3",
           "!!float 1", "<<x", "1.2.3", "sphere", "Sphere", "n", "N", "y", "Off", "a b", "-x", "+x", "'yes'",
           '"null"', "'1e5'", "~x", "<", "x" * 70, "'" + "y" * 70 + "'", "\"\"", "''", "!!bool true", "&a 5",
           "\"a\\nb\"", "#x", ".x", "0.5e+2", "NULL", "Null", "nullx", "truex"]


@pytest.mark.parametrize("scalar", SCALARS)
def test_scalars_read_as_pyyaml_reads_them(scalar):
    text = f"a: {scalar}\n"
    assert yamlfile.parse(text, "s.yaml") == yaml.load(text, Loader=_PyYAML)


def test_anchors_merges_and_nesting_read_as_pyyaml_reads_them():
    text = ("base: &b {x: 1, y: [1, 2, {z: 3}]}\nother: &o {y: 9, w: 4}\n"
            "m: {<<: [*b, *o], x: 7}\nn: {<<: *o}\nl: [*b, *o, [*b]]\nk: &k 5\nj: *k\n"
            "deep: {a: {b: {c: [[[]], {}]}}}\n")
    assert yamlfile.parse(text, "s.yaml") == yaml.load(text, Loader=_PyYAML)


@pytest.mark.parametrize("path", sorted(__import__("glob").glob(os.path.join(ROOT, "scenes", "*.yaml"))
                                        + __import__("glob").glob(os.path.join(ROOT, "bench", "*.yaml"))),
                         ids=os.path.basename)
def test_scene_files_read_as_pyyaml_reads_them(path):
    """The same tree, but for keys, which rtcli reads as text (an animation's keyframe times)."""
    text = open(path, encoding="utf-8").read()
    assert yamlfile.parse(text, path) == _keys_as_text(yaml.load(text, Loader=_PyYAML))


def _keys_as_text(x):
    if isinstance(x, dict):
        return {str(k): _keys_as_text(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_keys_as_text(v) for v in x]
    return x


@pytest.mark.parametrize("text, where, duplicates", [
    ("m: {a: 1, b: [2], c: {d: 3}}\n", {"a": (5, 8), "b": (11, 14), "c": (19, 22)}, 0),
    ("m: {a: 1, b: 2, <<: {c: 3, a: 9}, d: 4}\n", {"c": (22, 25), "a": (5, 8), "b": (11, 14), "d": (35, 38)}, 0),
    ("m: {<<: {c: 3}, a: 1}\n", {"c": (10, 13), "a": (17, 20)}, 0),
    ("m: {a: 1, b: 2, a: 3}\n", {"a": (17, 20), "b": (11, 14)}, 1),
])
def test_entries_keep_their_order_and_locations(text, where, duplicates):
    """A mapping's keys come in PyYAML's order (merged ones first, written ones winning), and each key
    and value keeps the column it was written at, with or without a merge key or a key given twice."""
    m = yamlfile.parse(text, "s.yaml")["m"]
    assert list(m) == list(where) and m == yaml.load(text, Loader=_PyYAML)["m"]
    assert {k: (m.key_where[k].column, m.value_where[k].column) for k in m} == where
    assert len(m.duplicates) == duplicates
