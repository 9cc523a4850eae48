"""Where an image came from: the text every image rtcli writes carries (README.md, Images).

A provenance is a dict of strings under the keys of KEYS: rtcli's version and the digest
of its sources, the scene file's path and SHA-256, the frame, size, samples, max depth,
block size, gamma, alpha, what the image holds (the color, a view, ids), the engine and
the render's time. The writer stores it as PNG text chunks, EXR header attributes, or JSON
in the TIFF, JPEG and WebP image description, and movie.py as an APNG's text chunks or a
GIF's comment (BMP, PPM and PFM have no place for it);
read() gets it back from any of them, and differences() says what two images' differ in,
for `rtcli compare`. The time and the engine never make a difference: the engines give the
same pixels, and no two renders take the same time.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from rtcli import __version__

PREFIX = "rtcli."
KEYS = ("version", "sources", "scene", "scene_sha256", "frame", "size", "samples", "max_depth", "block_size",
        "gamma", "alpha", "content", "engine", "render_seconds")
SETTINGS = ("scene_sha256", "frame", "size", "samples", "max_depth", "block_size", "gamma", "alpha", "content")
SOFTWARE = ("version", "sources")
DESCRIPTION = 270                         # TIFF/EXIF tags: ImageDescription holds the JSON, Software the name
SOFTWARE_TAG = 305

_digest: list = []


def sources_digest() -> str:
    """SHA-256 of every .py file of the rtcli package (each file's relative path and bytes, in
    order of path): the same sources give the same digest on any machine. Once a process."""
    if not _digest:
        package = Path(__file__).resolve().parent.parent
        digest = hashlib.sha256()
        for f in sorted(package.rglob("*.py")):
            digest.update(str(f.relative_to(package)).encode() + b"\0" + f.read_bytes())
        _digest.append(digest.hexdigest())
    return _digest[0]


def file_sha256(path: str) -> str:
    """The SHA-256 of a file's bytes, "-" when it cannot be read (a scene given as text or a dict)."""
    try:
        with open(path, "rb") as f:
            return hashlib.file_digest(f, "sha256").hexdigest() if hasattr(hashlib, "file_digest") \
                else hashlib.sha256(f.read()).hexdigest()
    except (OSError, TypeError, ValueError):
        return "-"


def provenance(scene: str, width: int, height: int, *, samples: int = 1, max_depth: int = 0, frame: int = 1,
               block_size: int = 1, gamma: bool = False, alpha: bool = False, content: str = "color",
               engine: str = "none", seconds: float = 0.0) -> dict[str, str]:
    """The provenance of an image of the scene file `scene` (a path, or "<string>"/"<dict>")."""
    values = dict(version=__version__, sources=sources_digest(), scene=str(scene),
                  scene_sha256=file_sha256(scene) if os.path.isfile(str(scene)) else "-", frame=frame,
                  size=f"{width}x{height}", samples=samples, max_depth=max_depth, block_size=block_size,
                  gamma=gamma, alpha=alpha, content=content, engine=engine, render_seconds=f"{seconds:.3f}")
    return {PREFIX + k: _text(values[k]) for k in KEYS}


def _text(value) -> str:
    return ("true" if value else "false") if isinstance(value, bool) else str(value)


def as_json(meta: dict[str, str]) -> str:
    """The provenance as one JSON object (TIFF, JPEG, WebP descriptions), keys in order."""
    return json.dumps(meta, ensure_ascii=False)


def software(meta: dict[str, str]) -> str:
    return f"rtcli {meta.get(PREFIX + 'version', __version__)}"


def from_json(text) -> dict[str, str]:
    """The provenance in an image description, {} when it holds none."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    try:
        found = json.loads(text) if isinstance(text, str) else None
    except ValueError:
        return {}
    if not isinstance(found, dict):
        return {}
    return {k: str(v) for k, v in found.items() if isinstance(k, str) and k.startswith(PREFIX)}


def ours(items) -> dict[str, str]:
    """The rtcli keys of a PNG's text or an EXR's header, as strings."""
    return {k: v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v)
            for k, v in items if isinstance(k, str) and k.startswith(PREFIX)}


def differences(actual: dict[str, str], expected: dict[str, str]) -> list[str]:
    """The note lines on what two images' provenances differ in (none when both lack one, or they
    agree): other settings, another rtcli, or only one of them with a provenance."""
    if not actual and not expected:
        return []
    if not actual or not expected:
        return [f"note: only the {'expected' if expected else 'actual'} image says how it was made "
                "(rtcli info shows it)"]
    lines = []
    for group, what in ((SETTINGS, "settings"), (SOFTWARE, "rtcli")):
        changed = [f"{k} {_short(actual.get(PREFIX + k))} (actual) vs {_short(expected.get(PREFIX + k))}"
                   for k in group if actual.get(PREFIX + k) != expected.get(PREFIX + k)]
        if changed:
            lines.append(f"note: made with different {what}: " + "; ".join(changed))
    return lines


def _short(value: str | None) -> str:
    if value is None:
        return "(none)"
    return value[:12] if len(value) == 64 and all(c in "0123456789abcdef" for c in value) else value


def lines(meta: dict[str, str]) -> list[str]:
    """`rtcli info`'s lines: each key (without the prefix) and its value, in KEYS order, then others."""
    keys = [PREFIX + k for k in KEYS if PREFIX + k in meta] + sorted(k for k in meta if k[len(PREFIX):] not in KEYS)
    width = max((len(k) - len(PREFIX) for k in keys), default=0)
    return [f"{k[len(PREFIX):]:<{width}}  {meta[k]}" for k in keys]
