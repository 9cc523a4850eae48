"""The bulk OBJ reader (rtcli/scenefile/obj_bulk.py) gives the careful reader's arrays, bit for
bit, or gives up and leaves the file to it; errors keep their file:line:column either way."""

import glob
import os

import numpy as np
import pytest

from rtcli.errors import SceneError
from rtcli.scenefile import obj_bulk
from rtcli.scenefile.obj import parse_obj, parse_obj_bytes, read_obj

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # tests/
MODELS = "/work/shared/models"
FILES = sorted(glob.glob(os.path.join(MODELS, "*.obj")) + glob.glob(os.path.join(HERE, "data", "*.obj"))
               + [os.path.join(HERE, "..", "bench", "torus100k.obj")])
NAMES = ("vertices", "uv", "normals", "faces", "uv_faces", "normal_faces")


def careful(data: bytes):
    return parse_obj(data.decode("utf-8", errors="replace"), "t.obj")


def assert_same(bulk, expected):
    """The bulk reader's six arrays equal the careful reader's: values, signs of zero, dtypes, shapes."""
    assert bulk is not None, "the bulk reader gave up"
    for name, got in zip(NAMES, bulk):
        want = getattr(expected, name)
        assert got.dtype == want.dtype and got.shape == want.shape, name
        np.testing.assert_array_equal(got, want, err_msg=name)
        if got.dtype.kind == "f":
            np.testing.assert_array_equal(np.signbit(got), np.signbit(want), err_msg=name)


@pytest.mark.parametrize("path", FILES, ids=os.path.basename)
def test_model_files_read_alike(path):
    if not os.path.exists(path):
        pytest.skip(f"{path} is not here")
    data = open(path, "rb").read()
    assert_same(obj_bulk.parse(data), careful(data))


QUAD = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
VARIANTS = {
    "triangle": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "no newline at the end": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3",
    "crlf": "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
    "tabs and spaces": "v\t0  0 0 \n  v 1\t0\t0\n\tv 0 1 0\t\n f  1 2   3 \n\n\n",
    "comments": "# a comment\nv 0 0 0 # the origin\nv 1 0 0#x\nv 0 1 0\n#f 9 9 9\nf 1 2 3 # a face\n# end",
    "comment with f and v inside": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 # f 1 2 3\n#v 5 5 5\n",
    "non-ascii comments": "# caf\u00e9 \u2603\nv 0 0 0 # \u00fc\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "w and colors": "v 1 2 3 1.0\nv 0 0 0 1 0.5 0.5 0.5\nv 1 1 1 2 x y\nf 1 2 3\n",
    "vt forms": QUAD + "vt 0.25\nvt 0.5 0.75\nvt 1 2 3\nvt .5 5.\nf 1/1 2/2 3/3 4/4\n",
    "corner forms": QUAD + "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\n"
                    "f 1/1/1 2/2/1 3/3/2\nf 1//2 3//1 4//1\nf 4/1 1/2 2/3\nf 1 2 3 4\nf 2/1/ 3/2/ 4/3/\n"
                    "f 1/ 2/ 3/\nf 1// 2// 3//\n",
    "polygons": "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4 5\nf 1 2 3 4\nf 6 1 2\n",
    "negative indices": QUAD + "f -4 -3 -2\nv 2 2 2\nf -1 -2 -3 -4\nvt 0 0\nvn 0 0 1\nf -1/-1/-1 -2/-1/-1 -3/-1/-1\n",
    "mixed statements": "mtllib m.mtl\no thing\ng a b\ns 1\nusemtl red\nv 0 0 0\nvp 0.5\nv 1 0 0\nl 1 2\n"
                        "v 0 0 1\np 1\nv1 9 9 9\nvtx 3\nff 1 2 3\nf 1 2 3\ncurv 0 1 1 2\n",
    "numbers": "v 1 -1 +1\nv .5 -.5 5.\nv -0 -0.0 +0.0\nv 1e5 1E-5 1.5e+3\nv -4.33681e-19 1e-22 1e22\n"
               "v 0.12345678901234567 123456789012345678 1234567890123456789012\nv 1e300 -1e-300 7e-320\n"
               "v 007.5 -00.25e02 9007199254740993\nv 2.5E0 3e00 0.000000000000000000000000123\nf 1 2 3\n",
    "leading zeros in indices": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 001 02 3\n",
    "no faces": "v 0 0 0\nv 1 1 1\n",
    "only comments": "# nothing here\n\n   \n",
    "empty": "",
    "vn and vt without faces": "vn 0 0 1\nvt 0 0\n",
}


@pytest.mark.parametrize("text", VARIANTS.values(), ids=VARIANTS.keys())
def test_variants_read_alike(text):
    data = text.encode()
    expected = careful(data)
    bulk = obj_bulk.parse(data)
    if text == "":
        assert bulk is None or all(len(x) == 0 for x in bulk)
        return
    assert_same(bulk, expected)


@pytest.mark.parametrize("fmt", ["%.17g", "%.6f", "%.3e", "%r", "%.20f", "%.1f", "%g"])
def test_random_numbers_read_alike(fmt):
    rng = np.random.default_rng(len(fmt))
    values = np.concatenate([rng.normal(0, 1, 3000), rng.normal(0, 1e6, 600), rng.uniform(-1, 1, 600) * 1e-9,
                             10.0 ** rng.integers(-30, 30, 600) * rng.uniform(-1, 1, 600), [0.0, -0.0, 1, -1]])
    values = values[: len(values) // 3 * 3].reshape(-1, 3).tolist()
    text = "".join("v " + " ".join(fmt % x for x in row) + "\n" for row in values)
    text += "".join(f"vn {fmt % a} {fmt % b} {fmt % c}\n" for a, b, c in values[:100])
    text += "".join(f"vt {fmt % a} {fmt % b}\n" for a, b, _ in values[:100])
    text += "f 1/1/1 2/2/2 3/3/3\n"
    assert_same(obj_bulk.parse(text.encode()), careful(text.encode()))


def test_blocks_and_pieces_join_as_one(monkeypatch):
    """A file read in many blocks and converted in many pieces reads as in one: negative indices
    and statements counted across blocks."""
    rng = np.random.default_rng(2)
    lines = []
    for k in range(400):
        lines.append("v %.6f %.6f %.6f # c\n" % tuple(rng.normal(size=3)))
        lines.append("vt %.4f %.4f\n" % tuple(rng.uniform(size=2)))
        if k >= 3:
            lines.append("f -1/-1 -2/%d -3/-3 %d\n" % (k, k - 1))
    data = "".join(lines).encode()
    expected = careful(data)
    monkeypatch.setattr(obj_bulk, "BLOCK", 300)
    monkeypatch.setattr(obj_bulk, "PIECE", 7)
    assert_same(obj_bulk.parse(data), expected)


GIVE_UP = {
    "a lone carriage return": b"v 0 0 0\rv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a carriage return at the end": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\r",
    "a form feed in a comment": b"# a\x0cv 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a group separator in a comment": b"# a\x1dv 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a next-line character in a comment": "# a\u0085v 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode(),
    "a line separator in a comment": "# a\u2028v 5 5 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode(),
    "a unit separator between numbers": b"v 0\x1f0 0\nv 1 0 0\nv 0 1 0 0\nf 1 2 3\n",
    "a non-breaking space between numbers": "v 0\u00a00 0\nv 1 0 0\nv 0 1 0 0\nf 1 2 3\n".encode(),
    "non-ascii in a group name": "g W\u00fcrfel\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode(),
    "latin-1 outside a comment": b"g caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a NUL byte": b"v 0 0 0\x00\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "underscores in a number": b"v 1_000 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a plus sign on an index": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\n",
    "infinity": b"v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "an overflowing number": b"v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "a huge index": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 1234567890123456789012\n",
    "a very long token": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ng " + b"x" * 100 + b"\n",
}


@pytest.mark.parametrize("data", GIVE_UP.values(), ids=GIVE_UP.keys())
def test_unusual_files_are_left_to_the_careful_reader(data):
    assert obj_bulk.parse(data) is None or data.endswith(b"x" * 100 + b"\n")
    try:
        expected = careful(data)
    except SceneError as e:
        with pytest.raises(SceneError) as got:
            parse_obj_bytes(data, "t.obj")
        assert str(got.value) == str(e)
        return
    got = parse_obj_bytes(data, "t.obj")
    assert_same([getattr(got, n) for n in NAMES], expected)


TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
ERRORS = [
    ("v 0 0\n", "t.obj:1:5: 'v' needs 3 numbers, got 2"),
    ("v 0 0 0\nv 1 x 0\n", "t.obj:2:5: bad number 'x' in 'v'"),
    ("vn 0 0 nan\n", "t.obj:1:8: bad number 'nan' in 'vn'"),
    ("vt\n", "t.obj:1:1: 'vt' needs 1 numbers, got 0"),
    (TRIANGLE + "f 1 2\n", "t.obj:4:5: a face needs at least 3 vertices, got 2"),
    (TRIANGLE + "f 1 2 4\n", "t.obj:4:7: vertex index 4 out of range: 3 vertices defined"),
    (TRIANGLE + "f -1 -2 -4\nv 1 1 1\n", "t.obj:4:9: vertex index -4 out of range: 3 vertices defined before this line"),
    (TRIANGLE + "f 0 1 2\n", "t.obj:4:3: vertex index 0 is not allowed (OBJ indices start at 1)"),
    (TRIANGLE + "vt 0 0\nf 1/1 2/2 3/1\n", "t.obj:5:7: texture index 2 out of range: 1 texture coordinates (vt) defined"),
    (TRIANGLE + "f 1//1 2//1 3//1\n", "t.obj:4:3: normal index 1 out of range: 0 normals (vn) defined"),
    (TRIANGLE + "f 1 2.0 3\n", "t.obj:4:5: bad index in face corner '2.0'"),
    (TRIANGLE + "vn 0 0 1\nf 1//1 2//1 3//x\n", "t.obj:5:13: bad index in face corner '3//x'"),
    (TRIANGLE + "f 1/1/1/1 2 3\n", "t.obj:4:3: bad face corner '1/1/1/1' (more than v/vt/vn)"),
    (TRIANGLE + "f 1 //1 3\n", "t.obj:4:5: face corner '//1' has no vertex index"),
    (TRIANGLE + "f 1 2 -\n", "t.obj:4:7: bad index in face corner '-'"),
    ("# comment\r\n" + TRIANGLE.replace("\n", "\r\n") + "f 1 2 9\r\n", "t.obj:5:7: vertex index 9 out of range: 3 vertices defined"),
    ("v 0 0 0 # x\n\tv 1 0 0\nv 0 1 0\n  f 1  2   x\n", "t.obj:4:12: bad index in face corner 'x'"),
]


@pytest.mark.parametrize("text, message", ERRORS)
def test_errors_from_a_file_are_located_as_before(tmp_path, text, message):
    (tmp_path / "t.obj").write_bytes(text.encode())
    with pytest.raises(SceneError) as e:
        read_obj(str(tmp_path / "t.obj"), "t.obj")
    assert str(e.value) == message
