"""Wavefront OBJ reader: the triangle data a `mesh:` object needs (docs/scene-format.md, Objects).

Read statements: `v x y z [w]` (w and trailing vertex colors ignored), `vt u [v [w]]`
(v defaults to 0), `vn x y z`, and `f` with corners `v`, `v/vt`, `v//vn` or `v/vt/vn`.
Indices are 1-based; negative ones count back from the last element defined
before the face's line. Polygons are fan-triangulated around their first corner,
which keeps the vertex order and so the outward normal. Comments (`#` to the end
of the line) and blank lines are skipped. Everything else (g, o, s, usemtl,
mtllib, l, p, curves, unknown statements) is ignored on purpose: the renderer
uses geometry only. Malformed lines raise SceneError at `file:line:column`.
Files are read by the bulk reader (obj_bulk.py, numpy over the whole file) when it
can; parse_obj here, the careful reader, reads the rest and names every error.
Numbers are converted in bulk by numpy; only the split into lines is a loop.
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass

import numpy as np

from rtcli.errors import SceneError, Where, quoted
from rtcli.scenefile import obj_bulk
from rtcli.scenefile.files import read_bytes
from rtcli.scenefile.limits import MAX_MAGNITUDE, MAX_MESH_BYTES, RANGE

_READ = {"v": 3, "vt": 1, "vn": 3}      # statement -> how many numbers it needs at least
_KEEP = {"v": 3, "vt": 2, "vn": 3}      # statement -> how many numbers are kept (vt's v defaults to 0)
_NAMES = (("vertex", "vertices"), ("texture", "texture coordinates (vt)"), ("normal", "normals (vn)"))
_MISSING = obj_bulk.MISSING                # an empty vt / vn field of a face corner
_MISSING_TEXT = str(_MISSING)


@dataclass(frozen=True)
class ObjData:
    """Triangles of an OBJ file, all indices 0-based; -1 marks a corner without vt / vn."""

    vertices: np.ndarray              # (V, 3) v positions
    faces: np.ndarray                 # (F, 3) vertex indices of the fan-triangulated faces
    uv: np.ndarray                    # (T, 2) vt coordinates, T may be 0
    uv_faces: np.ndarray              # (F, 3) vt index per corner, or -1
    normals: np.ndarray               # (N, 3) vn vectors as written (not normalized), N may be 0
    normal_faces: np.ndarray          # (F, 3) vn index per corner, or -1


class _Source:
    """The file's lines, to locate an error at a statement's k-th argument."""

    def __init__(self, display: str, lines: list[str]):
        self.display, self.lines = display, lines

    def error(self, line_no: int, arg: int, message: str) -> SceneError:
        tokens = list(re.finditer(r"\S+", self.lines[line_no - 1]))
        column = tokens[min(arg + 1, len(tokens) - 1)].start() + 1
        return SceneError(Where(self.display, line_no, column), "", message)


def parse_obj(text: str, display: str, bound: float = sys.float_info.max) -> ObjData:
    """Parse OBJ text; `display` names the file in error messages; a number beyond +-`bound` is
    an error (read_obj's bound is a scene's, +-MAX_MAGNITUDE)."""
    lines = text.splitlines()
    src, found = _Source(display, lines), _statements(lines)
    v, vt, vn = (_numbers(src, kw, *found[kw], bound) for kw in ("v", "vt", "vn"))
    line_of_f, args_of_f = found["f"]
    faces = np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64)
    if line_of_f:
        counts = [np.searchsorted(np.array(found[kw][0], np.int64), line_of_f) for kw in ("v", "vt", "vn")]
        faces = _faces(src, line_of_f, args_of_f, counts, (len(v), len(vt), len(vn)))
    return ObjData(v, faces[0], vt, faces[1], vn, faces[2])


def read_obj(path: str, display: str | None = None) -> ObjData:
    """Read and parse an OBJ file (OSError if it cannot be read, is not a regular
    file or is larger than MAX_MESH_BYTES).

    OBJ is ASCII; bytes that are not UTF-8 (in comments, say) are replaced, not refused.
    """
    return parse_obj_bytes(read_bytes(path, MAX_MESH_BYTES), display or path)


def parse_obj_bytes(data: bytes, display: str) -> ObjData:
    """An OBJ file's bytes: by the bulk reader (obj_bulk.py) when it can, else by parse_obj,
    which gives the same arrays and names any error at its line and column. Every number lies
    within +-MAX_MAGNITUDE, as a scene's (docs/scene-format.md, Limits): a vertex at 1e300
    would overflow the triangles' arithmetic."""
    bulk = obj_bulk.parse(data)
    if bulk is None:
        return parse_obj(data.decode("utf-8", errors="replace"), display, MAX_MAGNITUDE)
    v, vt, vn, faces, uv_faces, normal_faces = bulk
    if any(a.size and (a.max() > MAX_MAGNITUDE or a.min() < -MAX_MAGNITUDE) for a in (v, vt, vn)):
        parse_obj(data.decode("utf-8", errors="replace"), display, MAX_MAGNITUDE)     # names the number
    return ObjData(v, faces, vt, uv_faces, vn, normal_faces)


def _statements(lines: list[str]) -> dict[str, tuple[list[int], list[list[str]]]]:
    """Line numbers and argument lists of the v, vt, vn and f statements, in file order."""
    found = {kw: ([], []) for kw in ("v", "vt", "vn", "f")}
    for no, line in enumerate(lines, 1):
        if "#" in line:
            line = line[:line.index("#")]
        parts = line.split()
        if parts and parts[0] in found:
            where, args = found[parts[0]]
            where.append(no)
            args.append(parts[1:])
    return found


def _numbers(src: _Source, kw: str, line_nos: list[int], args: list[list[str]], bound: float) -> np.ndarray:
    """(k, 2 or 3) array of the leading numbers of every `kw` statement, all finite and within +-bound."""
    need, keep = _READ[kw], _KEEP[kw]
    for no, a in zip(line_nos, args):
        if len(a) < need:
            raise src.error(no, len(a), f"'{kw}' needs {need} numbers, got {len(a)}")
    flat = [x for a in args for x in (a + ["0"])[:keep]]
    try:
        out = np.array(flat, dtype=float).reshape(-1, keep)
    except ValueError:
        out = None
    if out is None or not (np.abs(out) <= bound).all():                # NaN and infinities fail it too
        for no, a in zip(line_nos, args):
            for k, x in enumerate(a[:keep]):
                if not _finite(x):
                    raise src.error(no, k, f"bad number {quoted(x)} in '{kw}'")
                if abs(float(x)) > bound:
                    raise src.error(no, k, f"number {x} in '{kw}' must be {RANGE}")
    return out


def _finite(x: str) -> bool:
    try:
        return bool(np.isfinite(float(x)))
    except ValueError:
        return False


def _faces(src, line_nos, args, counts, totals):
    """Fan-triangulated (F, 3) index arrays for v, vt and vn from the f statements."""
    corners = np.array([len(a) for a in args], np.int64)
    if (corners < 3).any():
        k = int(np.argmax(corners < 3))
        raise src.error(line_nos[k], corners[k], f"a face needs at least 3 vertices, got {corners[k]}")
    tokens = [t for a in args for t in a]
    line = np.repeat(np.asarray(line_nos, np.int64), corners)
    arg = np.arange(len(tokens)) - np.repeat(np.cumsum(corners) - corners, corners)

    def at(k, message):                     # error at flat corner k
        return src.error(int(line[k]), int(arg[k]), message)
    fields = _fields(tokens, at)
    if (fields[0] == _MISSING).any():
        k = int(np.argmax(fields[0] == _MISSING))
        raise at(k, f"face corner {quoted(tokens[k])} has no vertex index")
    idx = [_resolve(f, np.repeat(c, corners), n, names, at)
           for f, c, n, names in zip(fields, counts, totals, _NAMES)]
    tri = obj_bulk.fan(corners)
    return tuple(i[tri] for i in idx)


def _fields(tokens, at):
    """Split corners 'v', 'v/vt', 'v//vn', 'v/vt/vn' into three int arrays, _MISSING where empty."""
    if "/" not in " ".join(tokens):
        texts = [tokens, None, None]
    else:
        pad = ("//", "/", "")
        slashes = [t.count("/") for t in tokens]
        if max(slashes) > 2:
            k = int(np.argmax(np.array(slashes) > 2))
            raise at(k, f"bad face corner {quoted(tokens[k])} (more than v/vt/vn)")
        parts = "/".join(t + pad[s] for t, s in zip(tokens, slashes)).split("/")
        texts = [[x or _MISSING_TEXT for x in parts[j::3]] for j in range(3)]
    out = []
    for text in texts:
        if text is None:
            out.append(np.full(len(tokens), _MISSING, np.int64))
            continue
        try:
            out.append(np.array(text, dtype=np.int64))
        except (ValueError, OverflowError):
            k = next(i for i, x in enumerate(text) if not _is_index(x))
            raise at(k, f"bad index in face corner {quoted(tokens[k])}") from None
    return out


def _is_index(text: str) -> bool:
    """An integer that fits an int64 (the empty-field placeholder counts)."""
    try:
        return np.iinfo(np.int64).min <= int(text) <= np.iinfo(np.int64).max
    except ValueError:
        return False


def _resolve(raw, count_before, total, names, at):
    """0-based indices: i > 0 -> i - 1, i < 0 -> count_before + i, missing -> -1; 0 is an error."""
    if (raw == 0).any():
        k = int(np.argmax(raw == 0))
        raise at(k, f"{names[0]} index 0 is not allowed (OBJ indices start at 1)")
    idx = np.where(raw > 0, raw - 1, np.where(raw == _MISSING, -1, count_before + raw))
    bad = (idx >= total) | ((raw < 0) & (raw != _MISSING) & (idx < 0))
    if bad.any():
        k = int(np.argmax(bad))
        n, before = (total, "") if raw[k] > 0 else (int(count_before[k]), " before this line")
        raise at(k, f"{names[0]} index {raw[k]} out of range: {n} {names[1]} defined{before}")
    return idx
