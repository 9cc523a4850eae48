"""OBJ reading and the Mesh shape: same answers as the same triangles one by one."""

import os
import pickle

import numpy as np
import pytest

from rtcli.core.vec import unit3 as normalize
from rtcli.errors import SceneError
from rtcli.scenefile.obj import parse_obj, read_obj
from rtcli.scenefile.objects import shape_from
from rtcli.scenefile.params import Params
from rtcli.scenefile.yamlfile import parse
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.triangle import NA, Triangle

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data")
MODELS = "/work/shared/models"
TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


# --- OBJ reader ---
def test_quad_and_pentagon_are_fan_triangulated_and_the_rest_ignored():
    obj = read_obj(os.path.join(DATA, "polygons.obj"))
    assert obj.vertices.shape == (9, 3)
    np.testing.assert_array_equal(obj.faces, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [4, 7, 8]])
    assert obj.uv.shape == (0, 2) and obj.normals.shape == (0, 3)
    assert np.all(obj.uv_faces == -1) and np.all(obj.normal_faces == -1)


def test_corner_forms_v_vt_vn():
    text = (TRIANGLE + "vt 0 0\nvt 1 0\nvt 0 1 0\nvn 0 0 1\n"
            "f 1/1/1 2/2/1 3/3/1\nf 1//1 2//1 3//1\nf 1/3 2/2 3/1\nf 1 2 3\n")
    obj = parse_obj(text, "t.obj")
    np.testing.assert_array_equal(obj.faces, [[0, 1, 2]] * 4)
    np.testing.assert_array_equal(obj.uv_faces, [[0, 1, 2], [-1, -1, -1], [2, 1, 0], [-1, -1, -1]])
    np.testing.assert_array_equal(obj.normal_faces, [[0, 0, 0], [0, 0, 0], [-1, -1, -1], [-1, -1, -1]])
    np.testing.assert_array_equal(obj.uv, [[0, 0], [1, 0], [0, 1]])


def test_negative_indices_count_back_from_the_line():
    text = TRIANGLE + "f -3 -2 -1\nv 5 5 5\nf -4 -3 -1\nvt 0.5 0.5\nf 1/-1 2/-1 3/-1\n"
    obj = parse_obj(text, "t.obj")
    np.testing.assert_array_equal(obj.faces, [[0, 1, 2], [0, 1, 3], [0, 1, 2]])
    np.testing.assert_array_equal(obj.uv_faces[2], [0, 0, 0])


def test_vt_with_one_number_and_v_with_w():
    obj = parse_obj("v 1 2 3 1.0\nv 0 0 0\nv 1 1 1\nvt 0.25\nf 1/1 2/1 3/1\n", "t.obj")
    np.testing.assert_array_equal(obj.vertices[0], [1, 2, 3])
    np.testing.assert_array_equal(obj.uv, [[0.25, 0]])


@pytest.mark.parametrize("text, message", [
    ("v 0 0\n", "t.obj:1:5: 'v' needs 3 numbers, got 2"),
    ("v 0 0 0\nv 1 x 0\n", "t.obj:2:5: bad number 'x' in 'v'"),
    ("vn 0 0 nan\n", "t.obj:1:8: bad number 'nan' in 'vn'"),
    (TRIANGLE + "f 1 2\n", "t.obj:4:5: a face needs at least 3 vertices, got 2"),
    (TRIANGLE + "f 1 2 4\n", "t.obj:4:7: vertex index 4 out of range: 3 vertices defined"),
    (TRIANGLE + "f -1 -2 -4\nv 1 1 1\n",
     "t.obj:4:9: vertex index -4 out of range: 3 vertices defined before this line"),
    (TRIANGLE + "f 0 1 2\n", "t.obj:4:3: vertex index 0 is not allowed (OBJ indices start at 1)"),
    (TRIANGLE + "vt 0 0\nf 1/1 2/2 3/1\n",
     "t.obj:5:7: texture index 2 out of range: 1 texture coordinates (vt) defined"),
    (TRIANGLE + "f 1//1 2//1 3//1\n", "t.obj:4:3: normal index 1 out of range: 0 normals (vn) defined"),
    (TRIANGLE + "f 1 2.0 3\n", "t.obj:4:5: bad index in face corner '2.0'"),
    (TRIANGLE + "vn 0 0 1\nf 1//1 2//1 3//x\n", "t.obj:5:13: bad index in face corner '3//x'"),
    (TRIANGLE + "f 1/1/1/1 2 3\n", "t.obj:4:3: bad face corner '1/1/1/1' (more than v/vt/vn)"),
    (TRIANGLE + "f 1 //1 3\n", "t.obj:4:5: face corner '//1' has no vertex index"),
])
def test_malformed_lines_name_file_line_and_column(text, message):
    with pytest.raises(SceneError) as e:
        parse_obj(text, "t.obj")
    assert str(e.value) == message


def test_no_faces_is_empty_not_an_error():
    obj = parse_obj("# nothing\n\n" + TRIANGLE, "t.obj")
    assert obj.faces.shape == (0, 3)


# --- Mesh == individual triangles ---
def random_soup(rng, n):
    a = rng.uniform(-1, 1, (n, 3))
    return np.concatenate([a, a + rng.normal(0, 0.3, (n, 3)), a + rng.normal(0, 0.3, (n, 3))])


def test_intersect_equals_triangles_one_by_one():
    rng = np.random.default_rng(3)
    v = random_soup(rng, 80)
    faces = np.arange(240).reshape(3, 80).T
    mesh, triangles = Mesh(v, faces), [Triangle(*v[f]) for f in faces]
    o = rng.uniform(-1.5, 1.5, (3000, 3))
    d = rng.normal(size=(3000, 3))
    d[rng.random((3000, 3)) < 0.2] = 0.0
    d[np.all(d == 0, axis=1), 0] = 1.0
    t_max = rng.uniform(0.5, 4, 3000)
    t, prim = mesh.intersect(o, d, 1e-6, t_max)
    each = np.stack([tri.intersect(o, d, 1e-6, t_max)[0] for tri in triangles], axis=1)
    expected = each.min(axis=1)
    np.testing.assert_array_equal(t, expected)
    hit = np.isfinite(expected)
    unique = np.count_nonzero(each == expected[:, None], axis=1) == 1
    np.testing.assert_array_equal(prim[hit & unique], each.argmin(axis=1)[hit & unique])
    assert np.all(prim[~hit] == -1) and 0.05 < hit.mean() < 0.95
    np.testing.assert_array_equal(mesh.any_hit(o.T, d.T, 1e-6, t_max), hit)          # components (3, n)


def test_degenerate_triangles_are_skipped():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], float)
    mesh = Mesh(v, [[0, 1, 3], [0, 1, 2], [1, 1, 2]])          # collinear, good, repeated vertex
    assert len(mesh) == 1
    t, prim = mesh.intersect(np.array([[0.2, 0.2, 1]]), np.array([[0, 0, -1.0]]), 0, np.inf)
    assert t[0] == 1 and prim[0] == 0
    with pytest.raises(ValueError, match="zero area"):
        Mesh(v, [[0, 1, 3]])


# --- normals and uv ---
def test_flat_normal_is_the_face_normal_by_vertex_order():
    mesh = Mesh(np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0]], float), [[0, 1, 2]])
    p = np.array([[0.2, 0.2, 0.0]])
    np.testing.assert_array_equal(normalize(mesh.normal(p, np.array([0]))), [[0, 0, -1]])
    np.testing.assert_array_equal(mesh.geometric_normal(p, np.array([0])), [[0, 0, -1]])


def test_smooth_normals_interpolate_the_files_vn():
    obj = read_obj(os.path.join(DATA, "textured.obj"))
    mesh = Mesh(obj.vertices, obj.faces, True, obj.uv, obj.uv_faces, obj.normals, obj.normal_faces)
    p, prim = np.array([[0.5, 0.25, 0], [1, 1, 0]]), np.array([0, 0])
    n1, n2, n3 = normalize(np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1.0]]))
    expected = [0.5 * n1 + 0.25 * n2 + 0.25 * n3, n3]             # barycentrics of (0.5, 0.25): 0.5, 0.25, 0.25
    np.testing.assert_allclose(mesh.normal(p, prim), expected, atol=1e-15)
    np.testing.assert_array_equal(mesh.geometric_normal(p, prim), [[0, 0, 1], [0, 0, 1]])
    np.testing.assert_allclose(mesh.uv(p, prim), [[0.25, 0.125], [0.5, 0.5]], atol=1e-15)


def test_smooth_normals_without_vn_are_area_weighted_vertex_normals():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, -1]], float)
    faces = [[0, 1, 2], [0, 3, 1]]                              # z = 0 (area 1, +z) and y = 0 (area 1, -y)
    mesh = Mesh(v, faces, smooth=True)
    n = mesh.normal(np.array([[0.0, 0, 0], [0.0, 1, 0]]), np.array([0, 0]))
    np.testing.assert_allclose(n, [normalize(np.array([0, -1, 1.0])), [0, 0, 1]], atol=1e-15)
    flat = Mesh(v, faces, smooth=False)
    np.testing.assert_array_equal(flat.normal(np.zeros((1, 3)), np.array([0])), [[0, 0, 2]])


def test_uv_without_vt_is_barycentric_as_triangle():
    rng = np.random.default_rng(5)
    v = random_soup(rng, 5)
    mesh = Mesh(v, np.arange(15).reshape(3, 5).T)
    tri = Triangle(v[2], v[7], v[12])
    p = tri.a + 0.3 * (tri.b - tri.a) + 0.1 * (tri.c - tri.a)
    np.testing.assert_allclose(mesh.uv(p[None], np.array([2])), tri.uv(p[None], np.array([0])), atol=1e-12)


# --- built from YAML (rtcli.scenefile.objects.shape_from) ---
def mesh_params(tmp_path, body):
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"mesh: {body}\n")
    tree = parse(scene.read_text(), str(scene), str(tmp_path))
    return Params(tree["mesh"], "mesh")


def test_yaml_reads_a_file_relative_to_the_scene(tmp_path):
    (tmp_path / "m.obj").write_text(TRIANGLE + "f 1 2 3\n")
    mesh = shape_from(mesh_params(tmp_path, "{file: m.obj, smooth: true}"), Mesh)
    assert mesh.smooth and len(mesh) == 1      # smooth: true read
    np.testing.assert_array_equal(mesh.bounds()[1], [1, 1, 0])


@pytest.mark.parametrize("obj, message", [
    (None, "mesh.file: file not found: {tmp}/m.obj (looked for in {tmp}: a relative name starts from the folder "
           "of the file it is written in)"),
    ("# empty\n", "mesh.file: the mesh has no faces: {tmp}/m.obj"),
    (TRIANGLE + "f 1 1 2\n", "mesh.file: all triangles of the mesh have zero area: {tmp}/m.obj"),
])
def test_yaml_errors_point_at_file(tmp_path, obj, message):
    if obj is not None:
        (tmp_path / "m.obj").write_text(obj)
    with pytest.raises(SceneError) as e:
        shape_from(mesh_params(tmp_path, "{file: m.obj}"), Mesh)
    assert str(e.value) == f"{tmp_path}/scene.yaml:1:14: " + message.format(tmp=tmp_path)


def test_yaml_folder_and_latin1_comment(tmp_path):
    (tmp_path / "m.obj").write_bytes(b"# caf\xe9\n" + (TRIANGLE + "f 1 2 3\n").encode())
    assert len(shape_from(mesh_params(tmp_path, "{file: m.obj}"), Mesh)) == 1
    (tmp_path / "dir.obj").mkdir()
    with pytest.raises(SceneError, match=r"mesh\.file: cannot read .*dir\.obj: not a regular file but a folder"):
        shape_from(mesh_params(tmp_path, "{file: dir.obj}"), Mesh)


def test_yaml_obj_error_names_the_obj_file(tmp_path):
    (tmp_path / "m.obj").write_text(TRIANGLE + "f 1 2 7\n")
    with pytest.raises(SceneError, match=r"m\.obj:4:7: vertex index 7 out of range"):
        shape_from(mesh_params(tmp_path, "{file: m.obj}"), Mesh)


# --- real models ---
def test_bunny_loads_and_is_hit_like_brute_force():
    obj = read_obj(os.path.join(MODELS, "stanford-bunny.obj"))
    mesh = pickle.loads(pickle.dumps(Mesh(obj.vertices, obj.faces, smooth=True)))   # picklable for workers
    assert len(mesh) > 69000
    lo, hi = mesh.bounds()
    rng = np.random.default_rng(1)
    target = rng.uniform(lo, hi, (20, 3))
    o = np.broadcast_to((lo + hi) / 2 + [0, 0, 1.0], (20, 3))
    t, prim = mesh.intersect(o, target - o, 1e-9, np.inf)
    hit_pairs = mesh.pair_test(o.T, (target - o).T, 1e-9)
    for k in range(20):
        every = hit_pairs(np.full(len(mesh), k), np.arange(len(mesh)), np.inf)
        assert every.min() == t[k] and (np.isinf(t[k]) or every[prim[k]] == t[k])
    assert np.isfinite(t).sum() >= 5
    n = mesh.normal(o[:1] + t[:1, None] * (target[:1] - o[:1]), prim[:1])
    assert np.all(np.isfinite(n))


def test_models_with_vt_and_vn():
    spot = read_obj(os.path.join(MODELS, "spot.obj"))
    assert len(spot.uv) and np.all(spot.uv_faces >= 0)
    suzanne = read_obj(os.path.join(MODELS, "suzanne.obj"))
    assert len(suzanne.normals) and np.all(suzanne.normal_faces >= 0)
    mesh = Mesh(suzanne.vertices, suzanne.faces, True, normals=suzanne.normals, normal_faces=suzanne.normal_faces)
    assert mesh.smooth and np.all(np.any(mesh.pool[:, NA:NA + 9] != 0, axis=1))    # every face's corner normals


def test_a_missing_mesh_names_the_folder_it_was_looked_for_in(tmp_path, monkeypatch):
    """A mesh named in an include is looked for beside the include, not beside the scene: the
    error says where it looked and why."""
    import rtcli
    monkeypatch.chdir(tmp_path)
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "m.obj").write_text(TRIANGLE + "f 1 2 3\n")           # beside the scene: not used
    (tmp_path / "common").mkdir()
    (tmp_path / "common" / "mesh.yaml").write_text("objects:\n  - {mesh: {file: models/m.obj}}\n")
    (tmp_path / "s.yaml").write_text("include: [common/mesh.yaml]\n")
    with pytest.raises(SceneError) as e:
        rtcli.load_scene("s.yaml")
    assert str(e.value) == (f"common/mesh.yaml:2:19: objects[0].mesh.file: file not found: common/models/m.obj "
                            f"(looked for in {tmp_path}/common/models: a relative name starts from the folder of the "
                            "file it is written in)")
    with pytest.raises(SceneError) as e:
        rtcli.load_scene({"objects": [{"mesh": {"file": "m.obj"}}]}, folder="common")
    assert str(e.value) == (f"<dict>: objects[0].mesh.file: file not found: common/m.obj (looked for in "
                            f"{tmp_path}/common: a relative name starts from load_scene's folder, the current one "
                            "by default)")
