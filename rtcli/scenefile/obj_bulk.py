"""The bulk OBJ reader: the arrays of obj.parse_obj for the usual files, without a loop over lines.

numpy works on the file's bytes at once: it blanks the comments, finds the tokens
and the lines, picks out the v, vt, vn and f statements by their first token, and
converts their numbers and face corners from the digits themselves, one byte
position at a time for all tokens together. A number [sign] digits [. digits]
[e [sign] digits] is m x 10^p for an integer m; when m <= 2^53 and |p| <= 22, both
m and 10^|p| are exact doubles and IEEE arithmetic rounds their product or quotient
correctly, which gives the double float() reads, bit for bit (the fast path of
Clinger's algorithm). The few other numbers are read by numpy's conversion, as the
careful reader reads them all.

It gives up (returns None) on anything unusual, and obj.parse_obj, the careful
reader, then reads the file and names any error at its line and column: bytes other
than printable ASCII, tabs and line ends outside comments, a line break that is not
\\n or \\r\\n, a number in another form, a face corner that is not v, v/vt, v//vn or
v/vt/vn with plain indices, and every error (a statement short of numbers, an index
out of range or 0). tests/scenefile/test_obj_bulk.py checks that both readers give the same
arrays. The file is read in blocks of whole lines, and tokens converted in pieces, so
that the masks and tables stay small beside the file (docs/scene-format.md, Limits).
"""

from __future__ import annotations

import numpy as np

MISSING = np.iinfo(np.int64).min        # an empty vt / vn field of a face corner (obj.py uses it too)
_POW10 = 10.0 ** np.arange(23)          # exact doubles
_EXACT = 2 ** 53                         # integers up to here are exact doubles
_LF, _CR, _HASH, _MINUS, _PLUS, _DOT, _SLASH = 10, 13, 35, 45, 43, 46, 47
_TOKEN, _BLANK, _NEWLINE, _RETURN, _COMMENT, _OTHER = range(6)
_CLASS = np.full(256, _OTHER, np.uint8)  # each byte's class
_CLASS[33:127] = _TOKEN                 # printable ASCII
_CLASS[[32, 9, 10, 13, 35]] = _BLANK, _BLANK, _NEWLINE, _RETURN, _COMMENT
_BREAKS = (0x0B, 0x0C, 0x1C, 0x1D, 0x1E)  # line breaks for str.splitlines, not for this reader
BLOCK = 1 << 23                          # bytes read at once (whole lines): bounds the masks' memory
PIECE = 1 << 18                          # tokens converted at once: bounds the per-token arrays


class _GiveUp(Exception):
    """Something the bulk reader leaves to the careful one."""


def parse(data: bytes):
    """(v, vt, vn, faces, uv_faces, normal_faces) as obj.parse_obj makes them, or None."""
    try:
        return _parse(np.frombuffer(data, dtype=np.uint8))
    except _GiveUp:
        return None


def _parse(data):
    """The file block by block (each whole lines), then the faces' indices resolved at once."""
    numbers = {"v": [], "vt": [], "vn": []}
    faces, counts = [], {"v": 0, "vt": 0, "vn": 0}          # statements in the blocks read so far
    at = 0
    while at < len(data):
        end = len(data)
        if at + BLOCK < len(data):                             # to the end of the line the block's size reaches
            ends = np.flatnonzero(data[at + BLOCK:] == _LF)
            end = at + BLOCK + int(ends[0]) + 1 if len(ends) else len(data)
        _block(data[at:end], numbers, faces, counts)
        at = end
    v, vt, vn = (np.concatenate(numbers[kw]) if numbers[kw] else np.zeros((0, keep))
                 for kw, keep in (("v", 3), ("vt", 2), ("vn", 3)))
    if not faces:
        return (v, vt, vn, *(np.zeros((0, 3), np.int64) for _ in range(3)))
    corners = np.concatenate([f[0] for f in faces])
    tri = fan(corners)
    out = []
    for j, total in enumerate((len(v), len(vt), len(vn))):
        if all(f[1][j] is None for f in faces):                  # no vt (or vn) anywhere
            out.append(np.full(tri.shape, -1, np.int64))
            continue
        idx = np.concatenate([np.full(f[0].sum(), -1, np.int64) if f[1][j] is None else
                              _resolve(f[1][j], f[2][j], total) for f in faces])
        out.append(idx[tri])
    return (v, vt, vn, *out)


def _block(b, numbers, faces, counts):
    """One block of whole lines: its v, vt, vn numbers and its faces' fields, added to the lists."""
    kind = _CLASS[b]
    rare = np.flatnonzero(kind >= _RETURN)                   # \r, '#' and bytes outside printable ASCII
    is_newline = kind == _NEWLINE
    if len(rare):
        kind = _rare_bytes(b, kind, rare, is_newline)
    edges = np.flatnonzero(np.diff(np.concatenate(([False], kind == _TOKEN, [False])).view(np.int8)))
    starts, ends = edges[0::2], edges[1::2]                  # tokens [start, end)
    line = np.cumsum(is_newline, dtype=np.int32)[starts]    # line of each token in the block
    first = np.flatnonzero(np.diff(line, prepend=-1) != 0)  # first token of each line
    args = np.diff(first, append=len(starts)) - 1           # tokens after it
    width = ends[first] - starts[first]
    c0, c1 = b[starts[first]], b[np.minimum(starts[first] + 1, len(b) - 1)]
    kinds = {"v": (width == 1) & (c0 == ord("v")), "vt": (width == 2) & (c0 == ord("v")) & (c1 == ord("t")),
             "vn": (width == 2) & (c0 == ord("v")) & (c1 == ord("n")), "f": (width == 1) & (c0 == ord("f"))}
    lines = {}
    for kw, need, keep in (("v", 3, 3), ("vt", 1, 2), ("vn", 3, 3)):
        rows = np.flatnonzero(kinds[kw])
        lines[kw] = line[first[rows]]
        if (args[rows] < need).any():
            raise _GiveUp
        token = first[rows][:, None] + 1 + np.arange(keep)                     # (k, keep)
        present = np.arange(keep) < args[rows][:, None]                       # vt's v defaults to 0
        values = np.zeros(token.shape)
        values[present] = _pieces(_numbers, b, starts[token[present]], ends[token[present]])
        numbers[kw].append(values)
    rows = np.flatnonzero(kinds["f"])
    if len(rows):
        corners = args[rows]
        if (corners < 3).any():
            raise _GiveUp
        token = np.repeat(first[rows] + 1 - (np.cumsum(corners) - corners), corners) + np.arange(corners.sum())
        slashes = bool((b == _SLASH).any())
        fields = _pieces(lambda *a: _corners(*a, slashes), b, starts[token], ends[token])
        f_line, before = None, []
        for j, kw in enumerate(("v", "vt", "vn")):
            if (fields[j] == MISSING).all():
                fields[j] = None                                 # a field no corner has
            if fields[j] is None or not (fields[j] < 0).any():
                before.append(0)                                 # no negative index to count back from
                continue
            f_line = np.repeat(line[first[rows]], corners) if f_line is None else f_line
            before.append(counts[kw] + np.searchsorted(lines[kw], f_line))
        faces.append((corners, fields, before))
    for kw in counts:
        counts[kw] += len(lines[kw])


def _rare_bytes(b, kind, rare, is_newline):
    """The bytes' classes with the comments blanked. _GiveUp for a byte outside printable ASCII
    that is not in a comment, and for a line break other than \\n and \\r\\n anywhere:
    str.splitlines, which the careful reader uses, also ends lines at \\r, \\v, \\f,
    \\x1c-\\x1e, U+0085, U+2028 and U+2029, in comments too."""
    code, last = b[rare], len(b) - 1
    second, third = b[np.minimum(rare + 1, last)], b[np.minimum(rare + 2, last)]
    lone_return = (code == _CR) & ((second != _LF) | (rare == last))
    unicode_break = ((code == 0xC2) & (second == 0x85)) | \
        ((code == 0xE2) & (second == 0x80) & ((third == 0xA8) | (third == 0xA9)))
    if (lone_return | np.isin(code, _BREAKS) | unicode_break).any():
        raise _GiveUp
    hashes = rare[code == _HASH]
    if len(hashes):
        newline = np.flatnonzero(is_newline)
        line = np.searchsorted(newline, hashes)
        hashes = hashes[np.diff(line, prepend=-1) != 0]     # the first '#' of its line
        size = np.append(newline, len(b))[np.searchsorted(newline, hashes)] - hashes
        kind = kind.copy()
        kind[np.repeat(hashes - (np.cumsum(size) - size), size) + np.arange(size.sum())] = _BLANK
    if (kind[rare] == _OTHER).any():
        raise _GiveUp
    return kind


def _pieces(convert, b, starts, ends):
    """convert(b, starts, ends) on PIECE tokens at a time, its arrays (or lists of arrays) joined."""
    parts = [convert(b, starts[k:k + PIECE], ends[k:k + PIECE]) for k in range(0, max(len(starts), 1), PIECE)]
    if isinstance(parts[0], list):
        return [np.concatenate([p[j] for p in parts]) for j in range(len(parts[0]))]
    return np.concatenate(parts)


def _columns(b, starts, ends):
    """For k = 0, 1, ...: the k-th byte of every token, and which tokens are that long."""
    length = ends - starts
    last = len(b) - 1
    for k in range(int(length.max()) if len(length) else 0):
        yield k, b[np.minimum(starts + k, last)], k < length


def _numbers(b, starts, ends):
    """The tokens as doubles, each as float() reads it; _GiveUp for a token in another form.

    Each token's digits build its mantissa m and its exponent, and the value is m x 10^p,
    p being the exponent less the digits after the point."""
    n = len(starts)
    m, e = np.zeros(n, np.int64), np.zeros(n, np.int64)
    digits, exp_digits, after_point = np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64)
    point, in_exp, exp_negative = np.zeros(n, bool), np.zeros(n, bool), np.zeros(n, bool)
    sign_may, bad = np.ones(n, bool), np.zeros(n, bool)          # a sign may come first, or right after e
    for _, c, live in _columns(b, starts, ends):
        d = c.astype(np.int64) - 48
        digit = live & (d >= 0) & (d <= 9)
        mantissa_digit, exponent_digit = digit & ~in_exp, digit & in_exp
        if mantissa_digit.any():
            m = np.where(mantissa_digit, m * 10 + d, m)             # wraps past 18 digits: read below
            digits += mantissa_digit
            after_point += mantissa_digit & point
        if exponent_digit.any():
            e = np.where(exponent_digit, e * 10 + d, e)
            exp_digits += exponent_digit
        sign = live & ((c == _MINUS) | (c == _PLUS)) & sign_may
        exp_negative |= sign & in_exp & (c == _MINUS)
        dot = live & (c == _DOT) & ~point & ~in_exp
        point |= dot
        mark = live & ((c == ord("e")) | (c == ord("E"))) & ~in_exp
        in_exp |= mark
        bad |= live & ~(digit | sign | dot | mark)
        sign_may = mark
    if (bad | (digits == 0) | (in_exp & (exp_digits == 0))).any():
        raise _GiveUp
    p = np.where(exp_negative, -e, e) - after_point              # the value is m x 10^p
    exact = (digits <= 15) | ((digits <= 18) & (m <= _EXACT))
    exact &= (exp_digits <= 3) & (np.abs(p) <= 22)
    up = p >= 0
    with np.errstate(all="ignore"):
        value = np.where(up, m * _POW10[np.where(up & exact, p, 0)], m / _POW10[np.where(up | ~exact, 0, -p)])
    value = np.where(b[starts] == _MINUS, -value, value) if n else value
    if not exact.all():
        other = np.flatnonzero(~exact)
        texts = [bytes(b[s:t]).decode("ascii") for s, t in zip(starts[other].tolist(), ends[other].tolist())]
        value[other] = np.array(texts, dtype=float)             # as the careful reader converts them
        if not np.isfinite(value[other]).all():
            raise _GiveUp
    return value


def _corners(b, starts, ends, slashes=True):
    """The v, vt, vn fields of face corners v, v/vt, v//vn, v/vt/vn as int64 (MISSING where empty);
    `slashes`: whether there is a '/' to look for."""
    n = len(starts)
    first_slash, second_slash = ends.copy(), ends.copy()          # where fields 0 and 1 end
    for k, c, live in _columns(b, starts, ends) if slashes else ():
        slash = live & (c == _SLASH)
        if slash.any():
            if (slash & (second_slash < ends)).any():
                raise _GiveUp                                     # more than v/vt/vn
            second_slash = np.where(slash & (first_slash < ends), starts + k, second_slash)
            first_slash = np.where(slash & (first_slash == ends), starts + k, first_slash)
    vertex = _integers(b, starts, first_slash)
    if (vertex == MISSING).any():
        raise _GiveUp                                             # no vertex index
    texture = _integers(b, np.minimum(first_slash + 1, ends), second_slash)
    normal = _integers(b, np.minimum(second_slash + 1, ends), ends)
    return [vertex, texture, normal] if n else [np.zeros(0, np.int64)] * 3


def _integers(b, starts, ends):
    """Fields [-]digits as int64, MISSING for an empty one; _GiveUp for anything else."""
    n = len(starts)
    value, digits, bad = np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, bool)
    for k, c, live in _columns(b, starts, ends):
        d = c.astype(np.int64) - 48
        digit = live & (d >= 0) & (d <= 9)
        value = np.where(digit, value * 10 + d, value)
        digits += digit
        bad |= live & ~digit & ~((c == _MINUS) & (k == 0))
    negative = (ends > starts) & (b[np.minimum(starts, len(b) - 1)] == _MINUS)
    if (bad | (digits > 18) | (negative & (digits == 0))).any():
        raise _GiveUp
    return np.where(digits == 0, MISSING, np.where(negative, -value, value))


def _resolve(raw, before, total):
    """0-based indices as obj._resolve makes them; _GiveUp for 0 or an index out of range."""
    if (raw == 0).any():
        raise _GiveUp
    idx = np.where(raw > 0, raw - 1, np.where(raw == MISSING, -1, before + raw))
    if ((idx >= total) | ((raw < 0) & (raw != MISSING) & (idx < 0))).any():
        raise _GiveUp
    return idx


def fan(corners: np.ndarray) -> np.ndarray:
    """(F, 3) positions into the flat corner list: polygon k gives (0, j, j+1), j = 1 .. k-2."""
    first = np.cumsum(corners) - corners
    ntri = corners - 2
    base = np.repeat(first, ntri)
    j = np.arange(int(ntri.sum())) - np.repeat(np.cumsum(ntri) - ntri, ntri) + 1
    return np.stack([base, base + j, base + j + 1], axis=1)
