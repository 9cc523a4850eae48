"""The hint in an unknown key's message: what the key was probably meant to be.

Given a key its mapping does not allow, the message suggests, in this order, rtcli's
name for the lecture notes' name of an allowed key (`kd` is `diffuse`), the allowed
key it seems to misspell or abbreviate (`raduis` for `radius`), or, for a material's
key written on an object, that it belongs in the object's material
(docs/scene-format.md, "The notes' names"). A required key that is missing while a
misspelling of it is given is reported at the misspelling (params.Params.raw).
"""

from __future__ import annotations

import difflib

from rtcli.errors import quoted, shown

# The lecture notes' names for what rtcli calls otherwise (docs/scene-format.md, "The notes'
# names"): a hint when one is given where rtcli's name is allowed.
NOTES_NAMES = {
    "wl": "left", "wr": "right", "wt": "top", "wb": "bottom",              # the window (notes 000, 11.2)
    "f": "focal", "position": "eye", "lookat": "look_at",                   # the camera
    "ka": "ambient", "kd": "diffuse", "ks": "specular", "kr": "reflection", "kt": "transmission",
    "exponent": "shininess", "n": "shininess", "color": "diffuse",          # a material (notes 002, 004)
    "angle": "degrees",                                                     # a rotate step
}
# A material's keys, in the order of docs/scene-format.md (Materials): a material allows them, and
# one given to an object is hinted at as belonging in its material.
MATERIAL_KEYS = ("ambient", "diffuse", "specular", "shininess", "emission", "reflection", "transmission",
                 "ior", "shadow", "fresnel", "texture", "preset")


def misspells(given, key: str) -> bool:
    """Whether the key `given` looks like `key` misspelled, abbreviated or in the notes' words."""
    if not isinstance(given, str):
        return False
    return (NOTES_NAMES.get(given) == key or bool(difflib.get_close_matches(key, [given], n=1))
            or (len(given) >= 3 and key.startswith(given)))


def unknown_key_hint(key, allowed: list, meant: str | None = None) -> str:
    """' (...)': the lecture notes' name of an allowed key, the allowed key `key` seems to
    misspell (`meant`, or the closest), or, for a material's key given to an object, that it
    belongs in the material; '' when none fits."""
    notes = NOTES_NAMES.get(key) if isinstance(key, str) else None
    if notes in allowed:
        return f" (the notes' {shown(key)} is {quoted(notes)} in rtcli)"
    close = [meant] if meant else difflib.get_close_matches(str(key), allowed, n=1) or \
        [a for a in allowed if len(str(key)) >= 3 and a.startswith(str(key))][:1]
    if close:
        return f" (did you mean {quoted(close[0])}?)"
    if "material" in allowed and (notes or key) in MATERIAL_KEYS:
        said = f"the notes' {shown(key)} is {quoted(notes)} in rtcli, a key" if notes else f"{shown(key)} is a key"
        return f" ({said} of the object's material: material: {{{notes or key}: ...}})"
    return ""
