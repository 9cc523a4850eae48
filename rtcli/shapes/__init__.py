"""Shapes: generic geometry in object space, one small protocol.

Every shape class offers
    from_params(p: Params) -> Shape           build from its YAML mapping (errors located)
    intersect(o, d, t_min, t_max) -> (t, prim)
        o, d: (n, 3) ray origins and directions in object space (d not unit);
        t_max: (n,) array or float. t (n,) is the nearest root with
        t_min < t < t_max, inf where there is none; prim (n,) int says which
        surface or triangle was hit (None when the shape has one surface).
    normal(p, prim) -> (n, 3)   outward object-space normal at hit points p (any length)
    uv(p, prim) -> (n, 2)       texture coordinates (u, v) at p
    bounds() -> (lo, hi) | None object-space box, None when unbounded (planes)
Shapes that model a solid also offer, for CSG,
    spans(o, d) -> (t_in, prim_in, t_out, prim_out), each (n, k): the intervals
        along each ray that lie inside the solid, sorted, padded with inf.
Optional: geometric_normal(p, prim) when the shading normal differs (smooth triangles).
"""

from rtcli.shapes.box import Box
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.planar import Plane, Polygon, Square, Triangle
from rtcli.shapes.quadric import Cone, Cylinder
from rtcli.shapes.sphere import Sphere
from rtcli.shapes.torus import Torus

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
