"""Scene tree -> objects and their shapes (docs/scene-format.md, Objects).

Object ids are 1, 2, 3 ... in file order, depth first through groups; a csg or a
mesh is one object. Groups are flattened: each child gets the group's transform
after its own, and the group's material when it names none. A shape is built from
the keys its class lists in `params` (rtcli/shapes/base.py), read here. Materials
are materials.py's, transforms transforms.py's.
"""

from __future__ import annotations

import os

import numpy as np

from rtcli.core import transform as tf
from rtcli.core.objects import ObjectList, SceneObject
from rtcli.errors import SceneError, Where, shown
from rtcli.scenefile import params as required
from rtcli.scenefile import reuse
from rtcli.scenefile.arrays import MeshArrays, SphereArrays
from rtcli.scenefile.guards import bounded, check_count
from rtcli.scenefile.limits import MAX_MAGNITUDE, MAX_OBJECTS
from rtcli.scenefile.materials import material_ref
from rtcli.scenefile.named_files import read_mesh_file
from rtcli.scenefile.nodes import MapNode
from rtcli.scenefile.params import Params, as_params
from rtcli.scenefile.transforms import compose, transform_from
from rtcli.scenefile.yamlbulk import SphereRun
from rtcli.scenefile.yamlevents import Builder, Loader
from rtcli.shapes import SHAPES
from rtcli.shapes.base import REQUIRED, ParamError
from rtcli.shapes.csg import CSG, OPS, Child
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.sphere_block import SphereBlock

OBJECT_KINDS = tuple(SHAPES) + ("csg", "group")


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
            values[param.key] = read_mesh_file(p, param.key, files[param.key])
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
        self.objects = ObjectList()

    def add_all(self, items, parent: tf.Transform | None = None, material: int | None = None):
        for item, where, path in items:
            if type(item) is SphereRun:
                self.add_run(item, where, path, self.default if material is None else material)
                continue
            check_count(self.objects, where, path)
            self.add(as_params(item, where, path, "an object (a mapping with a shape key)"), parent,
                     self.default if material is None else material)

    def add_run(self, run: SphereRun, where, path: str, material: int) -> None:
        """A run of spheres read in bulk (yamlbulk.py; `path`: its first's), checked in bulk as
        add() checks each: the first that fails is read again the usual way, for its error."""
        prefix, first = path[:path.rindex("[")], int(path[path.rindex("[") + 1:-1])
        c, r = run.centers, run.radii
        bad = ~(np.abs(c) <= MAX_MAGNITUDE).all(axis=1) | ~((r > 0) & (r <= MAX_MAGNITUDE))
        worst = int(np.argmax(bad)) if bad.any() else len(run)
        room = MAX_OBJECTS - len(self.objects)
        if room < len(run) and room <= worst:
            check_count(range(MAX_OBJECTS), Where(where.file, int(run.lines[room]), run.column),
                        f"{prefix}[{first + room}]")
        if worst < len(run):
            self._line_again(run, worst, where.file, f"{prefix}[{first + worst}]", material)
        self.objects.add_block(SphereBlock(c, r, material, where.file, run.lines, run.column, prefix, first))

    def add_spheres(self, p: Params, parent, inherited: int) -> None:
        """A set of spheres given as arrays (arrays.py): one block, each sphere an object."""
        arrays = p.raw("spheres")
        p.known("name", "material", "materials")
        if parent is not None:
            raise p.error("spheres", "a set of spheres given as arrays cannot be moved by a group's transform")
        if len(self.objects) + len(arrays) > MAX_OBJECTS:
            raise p.error("spheres", f"too many objects: a scene holds at most {MAX_OBJECTS:,}")
        if arrays.index is None:
            p.known("materials")
            material = material_ref(p, "material", self.named, self.table, inherited)
        else:
            rows = np.array([material_ref(_one(item, where, p.folder, path), "material", self.named, self.table,
                                          inherited) for item, where, path in p.items("materials")], dtype=np.int64)
            if len(rows) == 0 or arrays.index.max(initial=0) >= len(rows):
                raise p.error("materials", f"material_index goes up to {arrays.index.max(initial=0)}, but "
                                           f"{len(rows)} materials are listed")
            material = rows[arrays.index]
        p.check_unused()
        label = p.path or "spheres"
        self.objects.add_block(SphereBlock(arrays.centers, arrays.radii, material, p.node.file, None, 0,
                                           f"{label}.spheres", 0))

    def _line_again(self, run: SphereRun, j: int, file: str, path: str, material: int) -> None:
        """Read sphere j of the run the usual way, which raises the error the bulk check found."""
        text = "\n" * (int(run.lines[j]) - 1) + run.line(j)
        seq = Builder(Loader(text), file, ".", text).document()
        self.add(as_params(seq[0], seq.item_where[0], path, "an object (a mapping with a shape key)"), None, material)
        raise SceneError(seq.item_where[0], path, "this sphere cannot be read")       # not reached: add() raised

    def add(self, p: Params, parent, inherited: int) -> None:
        if type(p.node.get("spheres")) is SphereArrays:
            return self.add_spheres(p, parent, inherited)
        kind = self._kind(p)
        p.string("name", "")
        world = bounded(p, compose(transform_from(p), parent))
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
        if type(p.node[kind]) is MeshArrays:                # a mesh given as arrays (arrays.py)
            p.known(kind)
            try:
                return Mesh(p.node[kind].vertices, p.node[kind].faces, p.node[kind].smooth)
            except ParamError as e:
                raise p.error(kind, str(e).replace("the mesh", "the mesh's arrays")) from None
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


def _one(item, where, folder: str, path: str) -> Params:
    """Params holding entry `path` of a `materials` list as its `material` key."""
    node = MapNode.empty(where, folder)
    node["material"] = item
    node.places.extend((node.places[0], node.places[0]))
    return Params(node, path)
