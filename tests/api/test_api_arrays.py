"""Scenes from arrays (docs/python-api.md): sets of spheres and meshes given as numpy arrays are the
scene their YAML gives, and wrong arrays are located errors."""

import numpy as np
import pytest

import rtcli
from rtcli.core.objects import sphere_blocks

CAMERA = {"eye": [0, 0, 30], "look_at": [0, 0, 0], "fov": 40}


def cloud(n=300, seed=2):
    rng = np.random.default_rng(seed)
    return np.round(rng.uniform(-8, 8, (n, 3)), 2), np.round(rng.uniform(0.2, 0.9, n), 2)


def base(objects) -> dict:
    return {"image": {"width": 48, "height": 36}, "camera": CAMERA, "lights": [{"position": [10, 20, 30]}],
            "materials": {"red": {"diffuse": [1, 0, 0]}, "blue": {"diffuse": [0, 0, 1]}}, "objects": objects}


def test_a_set_of_spheres_is_the_scene_its_yaml_gives():
    c, r = cloud()
    index = (c[:, 0] > 0).astype(np.int64)
    arrays = rtcli.load_scene(base([{"spheres": {"centers": c, "radii": r, "material_index": index},
                                     "materials": ["red", "blue"]}]))
    listed = rtcli.load_scene(base([{"sphere": {"center": list(p), "radius": float(q)},
                                     "material": ["red", "blue"][k]} for p, q, k in zip(c, r, index)]))
    assert [len(b) for _, b in sphere_blocks(arrays.model.objects)] == [300]
    a, b = arrays.model, listed.model
    assert len(a.objects) == len(b.objects) == 300
    for x, y in zip(a.objects, b.objects):
        assert x.id == y.id and x.kind == y.kind == "sphere"
        assert np.array_equal(x.shape.row, y.shape.row)
        assert a.materials.materials[x.material].name == b.materials.materials[y.material].name
    assert a.objects[12].where == "<dict>: objects[0].spheres[12]"
    assert np.array_equal(rtcli.render(arrays, engine="numpy"), rtcli.render(listed, engine="numpy"))


def test_a_mesh_of_arrays_is_the_mesh_its_obj_file_gives(tmp_path):
    vertices = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0.5]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    (tmp_path / "m.obj").write_text("".join(f"v {x} {y} {z}\n" for x, y, z in vertices) + "f 1 2 3\nf 1 3 4\n")
    arrays = rtcli.load_scene(base([{"mesh": {"vertices": vertices, "faces": faces}}]))
    filed = rtcli.load_scene(base([{"mesh": {"file": "m.obj"}}]), folder=str(tmp_path))
    assert np.array_equal(arrays.model.objects[0].shape.pool, filed.model.objects[0].shape.pool, equal_nan=True)
    assert np.array_equal(rtcli.render(arrays, engine="numpy"), rtcli.render(filed, engine="numpy"))


@pytest.mark.parametrize("spheres, message", [
    ({"centers": np.zeros((5, 2)), "radii": 1.0}, "objects[0].spheres.centers: must be an array of shape (n, 3), "
                                                  "got shape (5, 2)"),
    ({"centers": np.array([[0, 0, 0], [1, np.nan, 0]]), "radii": 1.0},
     "objects[0].spheres.centers: entries must be finite numbers between -1e20 and 1e20: centers[1][1] is nan"),
    ({"centers": np.zeros((3, 3)), "radii": np.array([1, -0.5, 1])},
     "objects[0].spheres.radii: radii must be > 0: radii[1] is -0.5"),
    ({"centers": np.zeros((3, 3)), "radii": np.ones(4)}, "objects[0].spheres.radii: must be an array of shape (3,)"),
    ({"centers": np.array([["a", "b", "c"]]), "radii": 1.0}, "must be an array of numbers, got an array of <U1"),
    ({"centers": np.zeros((3, 3)), "radius": 1.0}, "objects[0].spheres.radius: unknown key; allowed here: centers"),
    ({"centers": np.zeros((3, 3))}, "objects[0].spheres.radii: missing required key"),
])
def test_wrong_sphere_arrays_are_located_errors(spheres, message):
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(base([{"spheres": spheres}]))
    assert str(e.value).startswith("<dict>: ") and message in str(e.value)


def test_material_indices_must_name_a_listed_material():
    with pytest.raises(rtcli.SceneError, match="material_index goes up to 2, but 2 materials are listed"):
        rtcli.load_scene(base([{"spheres": {"centers": np.zeros((3, 3)), "radii": 1.0,
                                            "material_index": np.array([0, 1, 2])}, "materials": ["red", "blue"]}]))
    with pytest.raises(rtcli.SceneError, match=r"objects\[0\].materials\[1\].material: unknown material 'green'"):
        rtcli.load_scene(base([{"spheres": {"centers": np.zeros((3, 3)), "radii": 1.0,
                                            "material_index": np.array([0, 1, 0])}, "materials": ["red", "green"]}]))


@pytest.mark.parametrize("mesh, message", [
    ({"vertices": np.zeros((3, 3)), "faces": np.array([[0, 1, 3]])},
     "objects[0].mesh.faces: entries must be in 0..2 (counted from 0): faces[0][2] is 3"),
    ({"vertices": np.zeros((3, 3)), "faces": np.array([[0.0, 1, 2]])}, "must be an array of integers, got an array of float64"),
    ({"vertices": np.zeros((3, 3)), "faces": np.array([[0, 1, 2]])}, "objects[0].mesh: all triangles of the mesh's "
                                                                     "arrays have zero area"),
])
def test_wrong_mesh_arrays_are_located_errors(mesh, message):
    with pytest.raises(rtcli.SceneError) as e:
        rtcli.load_scene(base([{"mesh": mesh}]))
    assert message in str(e.value)
