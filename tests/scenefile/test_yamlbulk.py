"""Runs of spheres written one a line, read in bulk (scenefile/yamlbulk.py): the same scene and the
same errors as the usual way, which a huge RUN_MIN forces."""

import numpy as np
import pytest

from rtcli.core.objects import ObjectList, sphere_blocks
from rtcli.errors import SceneError
from rtcli.scenefile import yamlbulk
from rtcli.scenefile.load import load_scene

HEAD = ("image: {width: 32, height: 24}\ncamera: {eye: [0, 0, 30], look_at: [0, 0, 0], fov: 40}\n"
        "lights: [{position: [10, 10, 10]}]\nmaterials: {red: {diffuse: [1, 0, 0]}}\nobjects:\n")


def spheres(n: int, indent: str = "  ", seed: int = 3) -> list[str]:
    rng = np.random.default_rng(seed)
    lines = []
    for k in range(n):
        x, y, z = np.round(rng.uniform(-9, 9, 3), 2)
        r = [1, 0.5, 0.25, 2.0][k % 4]
        lines.append(f"{indent}- {{sphere: {{center: [{x}, {y}, {z}], radius: {r}}}}}")
    return lines


def write(tmp_path, text: str, name: str = "s.yaml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def both(path: str, monkeypatch):
    """(bulk, usual): the scene loaded with runs read in bulk, and the usual way."""
    bulk = load_scene(path)
    with monkeypatch.context() as m:
        m.setattr(yamlbulk, "RUN_MIN", 10 ** 9)
        usual = load_scene(path)
    return bulk, usual


def error_of(path: str, monkeypatch, usual: bool = False) -> str:
    with monkeypatch.context() as m:
        if usual:
            m.setattr(yamlbulk, "RUN_MIN", 10 ** 9)
        with pytest.raises(SceneError) as e:
            load_scene(path)
    return str(e.value)


def same_objects(a, b) -> None:
    assert len(a.objects) == len(b.objects)
    for x, y in zip(a.objects, b.objects):
        assert (x.id, x.name, x.kind, x.material, x.where, x.world_from_object) == \
               (y.id, y.name, y.kind, y.material, y.where, y.world_from_object)
        assert np.array_equal(x.shape.row, y.shape.row)
        assert np.array_equal(np.array(x.bounds(), dtype=float), np.array(y.bounds(), dtype=float), equal_nan=True)


def test_a_run_is_one_block_and_the_same_scene(tmp_path, monkeypatch):
    lines = ["  - {plane: {point: [0, -10, 0], normal: [0, 1, 0]}, material: red}"] + spheres(100) \
        + ["  - {sphere: {center: [0, 0, 0], radius: 3}, name: big}"]
    bulk, usual = both(write(tmp_path, HEAD + "\n".join(lines) + "\n"), monkeypatch)
    assert isinstance(bulk.objects, ObjectList)
    assert [(s, len(b)) for s, b in sphere_blocks(bulk.objects)] == [(1, 100)]
    assert sphere_blocks(usual.objects) == []
    same_objects(bulk, usual)
    assert bulk.objects[57].where.endswith(f"s.yaml:{6 + 57}:5: objects[57]")
    assert np.array_equal(bulk.boxes.lo, usual.boxes.lo, equal_nan=True)
    assert np.array_equal(bulk.boxes.hi, usual.boxes.hi, equal_nan=True)


def test_short_runs_and_other_lines_go_the_usual_way(tmp_path, monkeypatch):
    lines = spheres(10) + ["  - {sphere: {center: [1e3, 0, 0], radius: 1}}"] + spheres(70, seed=4) \
        + ["  - {sphere: {center: [.5, 007, -0], radius: 1.}}"] + spheres(65, indent="  ", seed=5)
    bulk, usual = both(write(tmp_path, HEAD + "\n".join(lines)), monkeypatch)   # no newline at the end
    assert [(s, len(b)) for s, b in sphere_blocks(bulk.objects)] == [(11, 70), (82, 65)]
    same_objects(bulk, usual)


def test_a_run_elsewhere_than_the_top_level_list_is_read_the_usual_way(tmp_path, monkeypatch):
    text = HEAD + "  - group:\n      objects:\n" + "\n".join(spheres(80, indent="        ")) + "\n"
    bulk, usual = both(write(tmp_path, text), monkeypatch)
    assert sphere_blocks(bulk.objects) == []
    same_objects(bulk, usual)


@pytest.mark.parametrize("bad, expect", [
    ("radius: -0.5", "objects[40].sphere.radius: must be > 0, got -0.5"),
    ("radius: 0", "objects[40].sphere.radius: must be > 0, got 0"),
    ("radius: 300000000000000000000.5", "objects[40].sphere.radius: must be between -1e20 and 1e20"),
])
def test_a_bad_value_in_a_run_gets_the_usual_error(tmp_path, monkeypatch, bad, expect):
    lines = spheres(100)
    lines[40] = lines[40].replace(lines[40][lines[40].index("radius"):-2], bad)
    path = write(tmp_path, HEAD + "\n".join(lines) + "\n")
    message = error_of(path, monkeypatch)
    assert message == error_of(path, monkeypatch, usual=True)
    assert expect in message and f"s.yaml:{6 + 40}:" in message


def test_a_center_out_of_range_in_a_run_gets_the_usual_error(tmp_path, monkeypatch):
    lines = spheres(100)
    lines[99] = "  - {sphere: {center: [1, 200000000000000000000.0, 3], radius: 1}}"
    path = write(tmp_path, HEAD + "\n".join(lines) + "\n")
    message = error_of(path, monkeypatch)
    assert message == error_of(path, monkeypatch, usual=True)
    assert "s.yaml:105:" in message and "objects[99].sphere.center[1]" in message


def test_too_many_objects_in_a_run_is_located_at_the_first_too_many(tmp_path, monkeypatch):
    from rtcli.scenefile import guards, objects
    monkeypatch.setattr(guards, "MAX_OBJECTS", 150)
    monkeypatch.setattr(objects, "MAX_OBJECTS", 150)
    path = write(tmp_path, HEAD + "\n".join(spheres(100) + spheres(100, seed=9)) + "\n")
    message = error_of(path, monkeypatch)
    assert message == error_of(path, monkeypatch, usual=True)
    assert "s.yaml:156:5: objects[150]: too many objects" in message


def test_a_syntax_error_after_a_run_is_the_usual_one(tmp_path, monkeypatch):
    path = write(tmp_path, HEAD + "\n".join(spheres(100)) + "\nbackground: [0, 0\n")
    message = error_of(path, monkeypatch)
    assert message == error_of(path, monkeypatch, usual=True)
    assert "invalid YAML" in message


def test_a_run_read_in_chunks_is_the_same(tmp_path, monkeypatch):
    monkeypatch.setattr(yamlbulk, "CHUNK", 16)
    lines = spheres(150)
    lines[70] = "  - {sphere: {center: [1, 2, 3], radius: 1e0}}"          # not plain: the usual way
    bulk, usual = both(write(tmp_path, HEAD + "\n".join(lines) + "\n"), monkeypatch)
    assert [(s, len(b)) for s, b in sphere_blocks(bulk.objects)] == [(0, 70), (71, 79)]
    same_objects(bulk, usual)


def test_an_animated_scene_keeps_its_run_in_every_frame(tmp_path, monkeypatch):
    from rtcli.scenefile.load import load_animation
    text = ("animation: {fps: 1, frames: 2}\n" + HEAD + "\n".join(spheres(80)) + "\n"
            "  - {sphere: {radius: 1}, transform: [{translate: {keys: {0: [0, 0, 0], 1: [0, 2, 0]}}}]}\n")
    animation, first, _ = load_animation(write(tmp_path, text))
    second = animation.scene(2)
    assert [len(b) for _, b in sphere_blocks(second.objects)] == [80] and len(second.objects) == 81
    assert second.objects[80].world_from_object.m[1, 3] == 2.0 and first.objects[80].world_from_object is None \
        or first.objects[80].world_from_object.m[1, 3] == 0.0
    assert np.array_equal(first.boxes.lo[:80], second.boxes.lo[:80])
