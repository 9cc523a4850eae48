"""Scene tree -> materials and their textures (docs/scene-format.md, Materials and Textures).

A material mapping starts from its `preset:` (presets.py) when it names one, and each
key given overrides; an object's `material:` is a name from `materials:` or such a
mapping inline. A texture is a checker or a picture (its file read by named_files.py).
"""

from __future__ import annotations

import difflib

from rtcli.core.materials import Material
from rtcli.core.textures import Checker, ImageTexture
from rtcli.errors import quoted, shown
from rtcli.scenefile import reuse
from rtcli.scenefile.hints import MATERIAL_KEYS
from rtcli.scenefile.named_files import load_texels
from rtcli.scenefile.params import Params
from rtcli.scenefile.presets import PRESETS
from rtcli.scenefile.values import describe


def material_from(p: Params) -> Material:
    """A material mapping: optional `preset:` first, then each key overrides."""
    p.known(*MATERIAL_KEYS)                                 # allowed, in the order of the docs
    base = {}
    if p.has("preset"):
        name = p.string("preset")
        if name not in PRESETS:
            close = difflib.get_close_matches(name, list(PRESETS), n=1)
            hint = f"did you mean {quoted(close[0])}? " if close else ""
            raise p.error("preset", f"unknown preset {quoted(name)} ({hint}`rtcli presets` lists them)")
        pre = PRESETS[name]
        base = dict(ambient=pre.ambient, diffuse=pre.diffuse, specular=pre.specular, shininess=pre.shininess)
    diffuse = p.coefficient("diffuse", base.get("diffuse", 0.8))
    texture = p.optional("texture")
    m = Material(
        ambient=p.coefficient("ambient", base.get("ambient", diffuse)),
        diffuse=diffuse,
        specular=p.coefficient("specular", base.get("specular", 0.0)),
        shininess=p.number("shininess", base.get("shininess", 32.0), non_negative=True),
        emission=p.color("emission", (0.0, 0.0, 0.0)),
        reflection=p.coefficient("reflection", 0.0, at_most=1),      # at most 1: no light grows along a path
        transmission=p.coefficient("transmission", 0.0, at_most=1),
        ior=p.number("ior", 1.0, positive=True),
        shadow=_shadow(p),
        fresnel=p.boolean("fresnel", False),
        texture=None if texture is None else reuse.reused(texture.node, None, lambda: texture_from(texture)),
    )
    p.check_unused()
    return m


def _shadow(p: Params):
    """`shadow:` true (the default: a full shadow), false (none) or filter (light passes, times kt)."""
    value = p.raw("shadow", True)
    if value not in (True, False, "filter"):
        raise p.error("shadow", f"must be true, false or filter, got {describe(value)}")
    return value


def texture_from(p: Params):
    kinds = [k for k in ("checker", "image") if p.has(k)]
    p.known("checker", "image")
    if not kinds:
        p.check_unused()                                    # a misspelt kind says so
    if len(kinds) != 1:
        raise p.error(None, "a texture needs exactly one of: checker, image")
    if kinds[0] == "checker":
        c = p.sub("checker")
        c.known("colors", "size")
        colors = c.items("colors")
        if len(colors) != 2:
            raise c.error("colors", f"must be a list of 2 colors, got {describe(c.node['colors'])}")
        c1, c2 = (c.color_value("colors", v, path, where) for v, where, path in colors)
        tex = Checker(c1, c2, c.number("size", 1.0, positive=True))
        c.check_unused()
    else:
        tex = ImageTexture(load_texels(p, "image"), p.boolean("repeat", True))
    p.check_unused()
    return tex


def material_ref(p: Params, key: str, named: dict, table: list, default: int) -> int:
    """The material row for `material:`: a name from `materials` or an inline mapping."""
    if not p.has(key):
        p.known(key)
        return default
    value = p.raw(key)
    if isinstance(value, str):
        if value not in named:
            raise p.error(key, f"unknown material {quoted(value)}{_material_hint(value, named)}")
        return named[value]
    table.append(material_from(p.sub(key)))
    return len(table) - 1


def _material_hint(name: str, named: dict) -> str:
    """' (...)' for an unknown material name: the closest defined one, that it is a preset, or
    which names are defined."""
    close = difflib.get_close_matches(name, list(named), n=1)
    if close:
        return f" (did you mean {quoted(close[0])}?)"
    if name in PRESETS:
        return f" ({shown(name)} is a preset: write material: {{preset: {shown(name)}}})"
    if not named:
        return " (the scene defines no materials)"
    names = [shown(n) for n in named]
    return f" (defined: {', '.join(names[:8])}{', ...' if len(names) > 8 else ''})"
