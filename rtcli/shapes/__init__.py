"""Shapes: generic geometry in object space, each in its own file (protocol: base.py).

SHAPES is the registry: the YAML key of each shape and its class. The scene-file
builder reads a shape's `params` under its key; both engines run its kernels; the
tests check every registered shape. Adding a shape is its file, a line here and a
row in docs/scene-format.md (docs/architecture.md walks through one). `csg` and
`group` are objects made of objects, built by the scene-file builder.
"""

from rtcli.shapes.box import Box
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.plane import Plane
from rtcli.shapes.polygon import Polygon
from rtcli.shapes.quadric import Cone, Cylinder
from rtcli.shapes.sphere import Sphere
from rtcli.shapes.square import Square
from rtcli.shapes.torus import Torus
from rtcli.shapes.triangle import Triangle

SHAPES = {
    "sphere": Sphere,
    "plane": Plane,
    "triangle": Triangle,
    "polygon": Polygon,
    "square": Square,
    "box": Box,
    "cylinder": Cylinder,
    "cone": Cone,
    "torus": Torus,
    "mesh": Mesh,
}
