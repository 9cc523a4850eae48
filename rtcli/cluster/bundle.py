"""The scene as the bytes of the files the client read (the YAML, includes, meshes, textures),
each keyed by the SHA-256 of its content, so the workers need no shared folder."""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass


# --- the scene as files ---
@dataclass(frozen=True)
class Bundle:
    """The files a scene was built from: (path as the loader named it, real path, SHA-256) each,
    and their bytes by digest."""

    scene_path: str
    manifest: tuple
    blobs: dict

    @staticmethod
    def of(scene_path: str, kept: dict) -> Bundle:
        """From the files rtcli.scenefile.files.collecting kept while the client loaded the scene."""
        manifest, blobs = [], {}
        for path, (real, data) in sorted(kept.items()):
            digest = hashlib.sha256(data).hexdigest()
            manifest.append((path, real, digest))
            blobs[digest] = data
        return Bundle(scene_path, tuple(manifest), blobs)

    @property
    def key(self) -> str:
        return hashlib.sha256(json.dumps([self.scene_path, self.manifest]).encode()).hexdigest()

    @property
    def size(self) -> int:
        return sum(len(b) for b in self.blobs.values())
