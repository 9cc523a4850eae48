"""Runs of plain spheres in a scene file read in bulk (docs/scene-format.md, "Big scenes").

A particle cloud is written one sphere a line, `- {sphere: {center: [x, y, z], radius: r}}`,
a million times. Read event by event, each line costs the YAML parser a dozen Python
calls and the scene a dozen Python objects; here a run of at least RUN_MIN such lines
(the same indentation, numbers written plainly) is found with numpy over the file's
bytes, its numbers read by numpy's parser, and the run stands in the YAML text as one
placeholder item followed by as many empty lines, so the parser sees every other line
where it was. The tree gets a `SphereRun` where the placeholder was; objects.py builds
it as one block of spheres (core/objects.py), checking its values in bulk and reading a
line that fails a check the usual way, so that its error is the one it always was.

What is read in bulk is read as the usual way reads it: a number is an integer
(`-?[1-9][0-9]{0,17}` or `0`) or a float `-?[0-9]+.[0-9]*`, the two forms the event
builder reads itself (yamlevents.py), each parsed to the nearest double by both. Any
other line, or a placeholder that does not come back as an item of the top-level
`objects:` list, leaves the file to the usual way, whole.
"""

from __future__ import annotations

import numpy as np

from rtcli.scenefile.nodes import SeqNode

RUN_MIN = 64                             # lines of a run: fewer go the usual way
_SKELETON = b"{sphere: {center: [, , ], radius: }}"     # a line without its numbers, dash and spaces
_NUMBER_CHARS = b"0123456789.-"
_TOKEN = "__rtcli_sphere_run_"
_INDENTS = 16                           # indentations of runs looked for, the least first
CHUNK = 65536                           # lines read at once
_TRIES = 8                              # rounds of taking lines that are not plain out of runs


class SphereRun:
    """Spheres written one a line from line `lines[0]` on: `centers` (n, 3), `radii` (n,),
    each line's number (1-based) and the column of its `{`; `text` the file's, to read a line
    again the usual way (objects.py)."""

    __slots__ = ("centers", "radii", "lines", "column", "text")

    def __init__(self, centers, radii, lines, column: int, text: str):
        self.centers, self.radii, self.lines, self.column, self.text = centers, radii, lines, column, text

    def __len__(self) -> int:
        return len(self.radii)

    def line(self, j: int) -> str:
        """The text of sphere j's line."""
        start = 0
        for _ in range(int(self.lines[j]) - 1):
            start = self.text.index("\n", start) + 1
        end = self.text.find("\n", start)
        return self.text[start:] if end < 0 else self.text[start:end]


def extract(text: str) -> tuple[str, list[SphereRun]]:
    """(text with each run replaced, the runs in order); (text, []) when there are none."""
    if len(text) < RUN_MIN * len(_SKELETON) or "sphere" not in text or _TOKEN in text or "*" in text:
        return text, []
    data = text.encode("utf-8")
    starts = np.concatenate(([0], np.flatnonzero(np.frombuffer(data, np.uint8) == 10) + 1, [len(data) + 1]))
    indent = _indents(data, starts)
    for _ in range(_TRIES):
        read = [(first, count, _chunked(data, starts, first, count, int(indent[first])))
                for first, count in _runs(indent)]
        bad = [first + j for first, _, (_, _, wrong) in read for j in wrong]
        if not bad:
            break
        indent[bad] = -1                             # those lines go the usual way; the runs again
    else:
        return text, []
    runs, pieces, last = [], [], 0
    for first, count, (centers, radii, _) in read:
        runs.append(SphereRun(centers, radii, np.arange(first + 1, first + count + 1), int(indent[first]) + 3, text))
        pieces += [data[last:starts[first]], b" " * int(indent[first]) + b"- " + f"{_TOKEN}{len(runs) - 1}".encode(),
                   b"\n" * count]
        last = min(int(starts[first + count]), len(data))
    if not runs:
        return text, []
    pieces.append(data[last:])
    return b"".join(pieces).decode("utf-8"), runs


def _indents(data: bytes, starts: np.ndarray) -> np.ndarray:
    """Each line's indentation when it is `- {sphere: ...}` with its numbers taken out, else -1."""
    skeletons = np.array(data.translate(None, _NUMBER_CHARS).split(b"\n"), dtype=object)    # `- ` becomes ` `
    sizes = np.fromiter(map(len, skeletons), np.int64, len(skeletons)) - len(_SKELETON) - 1
    indent = np.full(len(skeletons), -1)
    for size in np.unique(sizes[sizes >= 0])[:_INDENTS]:
        rows = np.flatnonzero(sizes == size)
        indent[rows[skeletons[rows] == b" " * (int(size) + 1) + _SKELETON]] = size
    maybe = np.flatnonzero(indent >= 0)
    dash = np.frombuffer(data, np.uint8)[starts[maybe] + indent[maybe]] == 45
    indent[maybe[~dash]] = -1
    return indent


def _runs(indent: np.ndarray) -> list[tuple[int, int]]:
    """(first line, count) of each run of at least RUN_MIN lines of the same indentation (0-based)."""
    change = np.flatnonzero(np.diff(indent) != 0) + 1
    bounds = np.concatenate(([0], change, [len(indent)]))
    return [(int(a), int(b - a)) for a, b in zip(bounds[:-1], bounds[1:]) if indent[a] >= 0 and b - a >= RUN_MIN]


def _chunked(data: bytes, starts: np.ndarray, first: int, count: int, indent: int):
    """_numbers of the run, CHUNK lines at a time (small scratch arrays, reused: fewer page faults)."""
    parts = [_numbers(data, starts, a, min(CHUNK, first + count - a), indent) for a in range(first, first + count, CHUNK)]
    wrong = [a - first + np.asarray(w, dtype=np.int64) for a, (_, _, w) in zip(range(first, first + count, CHUNK), parts)]
    if any(len(w) for w in wrong):
        return None, None, np.concatenate(wrong)
    return np.concatenate([c for c, _, _ in parts]), np.concatenate([r for _, r, _ in parts]), []


def _numbers(data: bytes, starts: np.ndarray, first: int, count: int, indent: int):
    """(centers, radii, []) of the run's lines, or (None, None, lines of the run whose numbers are
    not all written plainly)."""
    begin, end = int(starts[first]), min(int(starts[first + count]), len(data))
    chars = np.frombuffer(data, np.uint8, end - begin, begin).copy()
    lines = starts[first:first + count] - begin
    chars[lines + indent] = 32                                          # the dash of `- {`
    digit = (chars >= 48) & (chars <= 57)
    number = digit | (chars == 46) | (chars == 45)
    before, after = np.empty_like(number), np.empty_like(number)       # the char before each, and after
    before[0], before[1:], after[-1], after[:-1] = False, number[:-1], False, number[1:]
    at, ends = np.flatnonzero(number & ~before), np.flatnonzero(number & ~after) + 1   # each number's bounds
    per_line = np.bincount(np.searchsorted(lines, at, "right") - 1, minlength=count)
    if np.any(per_line != 4):
        return None, None, np.flatnonzero(per_line != 4)
    wrong = _not_plain(chars, digit, at, ends)
    if wrong.any():
        return None, None, np.unique(np.flatnonzero(wrong) // 4)
    chars[~number] = 32
    del digit, number, before, after
    values = np.fromstring(chars.tobytes(), sep=" ").reshape(count, 4)      # each the nearest double, as float()
    return np.ascontiguousarray(values[:, :3]), values[:, 3].copy(), []


def _not_plain(chars, digit, at, ends) -> np.ndarray:
    """Which numbers ([at, ends) of chars) are not `-?[1-9][0-9]{0,17}`, `0` or `-?[0-9]+.[0-9]*`."""
    def numbers_of(positions):
        return np.bincount(np.searchsorted(at, positions, "right") - 1, minlength=len(at))
    dots = np.flatnonzero(chars == 46)
    minus = np.flatnonzero(chars == 45)
    dots_in, signed = numbers_of(dots), chars[at] == 45
    misplaced = numbers_of(minus) - signed + numbers_of(dots[~digit[dots - 1]])   # a minus only first, a digit before a dot
    digits = ends - at - dots_in - signed
    whole = dots_in == 0
    zero_first = (chars[at + signed] == 48) & whole
    return (misplaced > 0) | (dots_in > 1) | (digits == 0) | (zero_first & ((digits > 1) | signed)) | \
        (whole & (digits > 18))


def place(tree, runs: list[SphereRun]) -> bool:
    """Put each run where its placeholder is, in the top-level `objects:` list; False when a
    placeholder is elsewhere or missing (the file is then read the usual way)."""
    objects = tree.get("objects") if isinstance(tree, dict) else None
    if not isinstance(objects, SeqNode):
        return False
    found = 0
    for k, item in enumerate(objects):
        if type(item) is str and item.startswith(_TOKEN):
            if found == len(runs) or item != f"{_TOKEN}{found}" or runs[found].lines[0] != objects.places[k + 1] >> 32:
                return False
            objects[k] = runs[found]
            found += 1
    return found == len(runs)
