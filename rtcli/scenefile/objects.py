"""Scene tree -> materials, textures, transforms and objects (the YAML side of them).

Object ids are 1, 2, 3 ... in file order, depth first through groups; a csg or a
mesh is one object. Groups are flattened: each child gets the group's transform
after its own, and the group's material when it names none. A shape is built from
the keys its class lists in `params` (rtcli/shapes/base.py), read here.
"""

from __future__ import annotations

import difflib
import os

import numpy as np
from PIL import UnidentifiedImageError

from rtcli.core import transform as tf
from rtcli.core.materials import Material
from rtcli.core.scene import SceneObject
from rtcli.core.textures import Checker, ImageTexture
from rtcli.errors import SOURCES, SceneError, quoted, shown
from rtcli.scenefile import params as required
from rtcli.scenefile import reuse
from rtcli.scenefile.files import open_image
from rtcli.scenefile.guards import bounded, check_count, scale_factors
from rtcli.scenefile.limits import MAX_MESH_BYTES
from rtcli.scenefile.obj import read_obj
from rtcli.scenefile.hints import MATERIAL_KEYS
from rtcli.scenefile.params import Params, as_params
from rtcli.scenefile.presets import PRESETS
from rtcli.scenefile.values import describe
from rtcli.scenefile.yamlfile import MapNode
from rtcli.shapes import SHAPES
from rtcli.shapes.base import REQUIRED, ParamError
from rtcli.shapes.csg import CSG, OPS, Child

OBJECT_KINDS = tuple(SHAPES) + ("csg", "group")
STEPS = ("scale", "rotate", "translate", "matrix")          # the kinds of transform step


# --- materials ---
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


def load_texels(p: Params, key: str) -> np.ndarray:
    """The picture's texels (h, w, 3) as bytes, copied out of Pillow in bands of rows, so that
    loading holds Pillow's decoded image and one more byte array, not a float copy."""
    path = os.path.join(p.folder, p.string(key))
    try:
        with open_image(path) as img:
            rgb = img if img.mode == "RGB" else img.convert("RGB")
            w, h = rgb.size
            texels = np.empty((h, w, 3), dtype=np.uint8)
            band = max(1, (1 << 22) // max(w, 1))                     # about 12 MB a band
            for y in range(0, h, band):
                texels[y:y + band] = np.asarray(rgb.crop((0, y, w, min(h, y + band))))
            return texels
    except FileNotFoundError:
        raise not_found(p, key, path) from None
    except (UnidentifiedImageError, OSError) as e:
        raise p.error(key, f"cannot read image {shown(path)}: {e}") from None


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


# --- transforms ---
def transform_from(p: Params) -> tf.Transform | None:
    """The `transform:` list, composed in the order written (first listed applies first)."""
    if not p.has("transform"):
        p.known("transform")
        return None
    total = tf.Transform.identity()
    for item, where, path in p.items("transform"):
        step = as_params(item, where, path, "a mapping with one of: scale, rotate, translate, matrix")
        total = total.then(_one_transform(step))
    return bounded(p, total)


def _one_transform(p: Params) -> tf.Transform:
    keys = list(p.node)
    if len(keys) == 1 and keys[0] not in STEPS:
        p.known(*STEPS)
        p.check_unused()
    if len(keys) != 1:
        raise p.error(None, "each transform step is one of: scale, rotate, translate, matrix")
    kind = keys[0]
    try:
        if kind == "translate":
            return tf.translate(p.vector("translate"))
        if kind == "scale":
            value = p.raw("scale")
            s = p.number("scale") if not isinstance(value, list) else p.vector("scale")
            return tf.scale(scale_factors(p, s))
        if kind == "rotate":
            r = p.sub("rotate")
            r.known("axis", "degrees")
            axis, degrees = r.vector("axis"), r.number("degrees")
            r.check_unused()
            if not np.any(axis):
                raise r.error("axis", "must not be the zero vector")
            return tf.rotate(axis, degrees)
        return tf.Transform.from_matrix(_matrix(p))
    except ValueError as e:
        raise p.error(kind, str(e)) from None


def _matrix(p: Params) -> np.ndarray:
    rows = p.items("matrix")
    if len(rows) not in (3, 4):
        raise p.error("matrix", f"must be 3 or 4 rows of 4 numbers, got {describe(p.node['matrix'])}")
    m = np.eye(4)
    for k, (row, where, path) in enumerate(rows):
        m[k] = p.item_numbers(p.node["matrix"], k, row, 4, "a row of 4 numbers", path)
    if not np.array_equal(m[3], [0, 0, 0, 1]):
        raise p.error("matrix", "the 4th row must be [0, 0, 0, 1] (affine transforms only)")
    return m


# --- shapes ---
def shape_from(p: Params, cls):
    """A shape of class `cls` from its mapping: each of cls.params read and checked, then the
    shape made from the values; its own consistency errors are located at the key they blame."""
    values, files = {}, {}
    p.known(*(param.key for param in cls.params))
    for param in cls.params:
        default = required.REQUIRED if param.default is REQUIRED else param.default
        if param.kind == "obj":
            files[param.key] = os.path.normpath(os.path.join(p.folder, p.string(param.key)))
            values[param.key] = _read_mesh_file(p, param.key, files[param.key])
        elif param.kind == "number":
            values[param.key] = p.number(param.key, default, positive=param.positive,
                                         non_negative=param.non_negative)
        elif param.kind == "vector":
            values[param.key] = p.vector(param.key, default)
        elif param.kind == "vectors":
            values[param.key] = p.vectors(param.key, param.min_count, param.count, default)
        elif param.kind == "boolean":
            values[param.key] = p.boolean(param.key, default)
        else:
            raise TypeError(f"unknown parameter kind {param.kind!r}")
    try:
        return reuse.shape(cls, values, files, lambda: cls.from_values(**values))     # a watch's unchanged mesh
    except ParamError as e:
        key = next((k for k in e.keys if p.has(k)), e.keys[-1])
        raise p.error(key, f"{e}: {shown(files[key])}" if key in files else str(e)) from None


def _read_mesh_file(p: Params, key: str, path: str):
    try:
        return reuse.file_data(path, MAX_MESH_BYTES, lambda: read_obj(path))
    except FileNotFoundError:
        raise not_found(p, key, path) from None
    except OSError as e:
        raise p.error(key, f"cannot read {shown(path)}: {e.strerror or e}") from None


def not_found(p: Params, key: str, path: str) -> SceneError:
    """A mesh or texture file that is not there, with the folder it was looked for in and why
    there: a relative name is relative to the folder of the file that names it (an include's,
    not the scene's; for YAML text or a dict, load_scene's folder), and to no other."""
    if os.path.isabs(p.string(key)):
        return p.error(key, f"file not found: {shown(path)}")
    base = "load_scene's folder, the current one by default" if p.node.file in SOURCES else \
        "the folder of the file it is written in"
    looked = shown(os.path.abspath(os.path.dirname(path)))
    return p.error(key, f"file not found: {shown(path)} (looked for in {looked}: a relative name starts from {base})")


def csg_from(p: Params, builder: "ObjectBuilder", material: int) -> CSG:
    ops = [k for k in OPS if p.has(k)]
    p.known(*OPS)
    if not ops:
        p.check_unused()                                    # a misspelt operation says so
    if len(ops) != 1:
        raise p.error(None, "a csg needs exactly one of: union, intersection, difference")
    items = p.items(ops[0])
    if len(items) < 2:
        raise p.error(ops[0], f"needs at least 2 objects, got {len(items)}")
    children = []
    for item, where, path in items:
        cp = as_params(item, where, path, "an object (a mapping with a shape key)")
        shape, t, mat = builder.child(cp, material)
        if not shape.solid:
            raise cp.error(None, "a csg child must be a solid: sphere, plane, box, "
                           "cylinder, cone (capped), torus or csg")
        children.append(Child(shape, t, mat))
    return CSG(ops[0], children)


# --- objects ---
class ObjectBuilder:
    """Builds SceneObjects from `objects:` lists, numbering them 1, 2, 3 ..."""

    def __init__(self, named: dict, table: list, default_material: int):
        self.named, self.table, self.default = named, table, default_material
        self.objects: list[SceneObject] = []

    def add_all(self, items, parent: tf.Transform | None = None, material: int | None = None):
        for item, where, path in items:
            check_count(self.objects, where, path)
            self.add(as_params(item, where, path, "an object (a mapping with a shape key)"), parent,
                     self.default if material is None else material)

    def add(self, p: Params, parent, inherited: int) -> None:
        kind = self._kind(p)
        p.string("name", "")
        world = bounded(p, _compose(transform_from(p), parent))
        material = material_ref(p, "material", self.named, self.table, inherited)
        if kind == "group":
            g = self._shape_params(p, kind)
            self.add_all(g.items("objects"), world, material)
            g.check_unused()
        else:
            shape = self.shape(p, kind, material)
            self.objects.append(SceneObject(len(self.objects) + 1, p.node.get("name", ""), shape,
                                            material, world, kind, f"{p.where}: {p.path}"))
        p.check_unused()

    def shape(self, p: Params, kind: str, material: int):
        sp = self._shape_params(p, kind)
        if kind == "csg":                 # its children's inline materials join the table in every frame
            return self._new_shape(sp, kind, material)
        return reuse.reused(p.node[kind] if p.node[kind] is not None else p.node, kind,
                      lambda: self._new_shape(sp, kind, material))

    def _new_shape(self, sp: Params, kind: str, material: int):
        shape = csg_from(sp, self, material) if kind == "csg" else shape_from(sp, SHAPES[kind])
        sp.check_unused()
        return shape

    def child(self, p: Params, inherited: int):
        """(shape, world_from_object, material) of a csg child, which gets no id of its own."""
        kind = self._kind(p)
        if kind == "group":
            raise p.error("group", "a csg child must be a shape or a csg, not a group")
        p.string("name", "")
        t = transform_from(p)
        material = material_ref(p, "material", self.named, self.table, inherited)
        shape = self.shape(p, kind, material)
        p.check_unused()
        return shape, t, material

    @staticmethod
    def _kind(p: Params) -> str:
        kinds = [k for k in p.node if k in OBJECT_KINDS]
        if len(kinds) > 1:
            raise SceneError(p.node.key_where[kinds[1]], p.key_path(kinds[1]),
                             f"an object has one shape, but '{kinds[0]}' is already given")
        if not kinds:
            p.known("name", "material", "transform", *OBJECT_KINDS)
            p.check_unused()
            raise p.error(None, f"missing shape: one of {', '.join(OBJECT_KINDS)}")
        return kinds[0]

    @staticmethod
    def _shape_params(p: Params, kind: str) -> Params:
        if p.node[kind] is None:
            p.known(kind)
            return Params(MapNode.empty(p.node.value_where[kind], p.folder), p.key_path(kind))
        return p.sub(kind)


def _compose(own: tf.Transform | None, parent: tf.Transform | None) -> tf.Transform | None:
    if own is None:
        return parent
    return own if parent is None else own.then(parent)

