"""`rtcli validate`'s listing of objects and its warnings (README.md, `validate`).

A warning is a likely mistake that is not an error: the scene renders, but probably
not as meant. Each is located where the scene file gives what it is about:

- a color written as 0-255 values (recorded while loading, scenefile/remarks.py);
- no lights; no objects;
- a camera that sees no object: none lies wholly in view, and no primary ray of a small
  image hits one;
- a light inside a closed object that casts full shadows: it lights nothing outside;
- an object no light reaches: at the nearest point of its box, every light's
  attenuated intensity max(I) / (c0 + c1 r + c2 r^2) is below 1/255 (the 8-bit step),
  or the light is a spot whose cone misses the sphere around the box.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rtcli.core.objects import object_materials
from rtcli.core.scene import Scene
from rtcli.errors import RtcliError, one_line, plural, shown
from rtcli.scenefile.remarks import Remark, Remarks
from rtcli.wavefront.intersect import find_first_hit, nearest_over, no_hits
from rtcli.wavefront.rays import camera_rays

SMALL = 64                         # the camera check's signature is SMALL pixels on its long side,
LARGER = 512                       # then LARGER when that sees nothing (a small object can hide between rays)
DARK = 1 / 255                     # less light than this adds less than one step to an 8-bit pixel
LISTED = 20                        # warnings of one kind shown one by one; the rest are counted
PROBE = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)     # a direction no box face is parallel to


@dataclass(frozen=True)
class ObjectRow:
    """One line of `rtcli validate --objects`."""

    id: int
    name: str
    shape: str
    material: str                  # its name in `materials:`, "inline", or "default"
    shadow: str                    # true, false or filter
    triangles: int | None          # for meshes
    bounds: tuple | None           # world-space (lo, hi), None when unbounded


def object_rows(scene: Scene) -> list[ObjectRow]:
    """One row per object, in id order."""
    rows = []
    for o in scene.objects:
        material = scene.materials.materials[o.material]
        name = material.name or ("default" if o.material == 0 else "inline")
        triangles = len(o.shape) if o.kind == "mesh" else None
        rows.append(ObjectRow(o.id, o.name, o.kind, name, str(material.shadow).lower(), triangles, o.bounds()))
    return rows


def object_lines(rows: list[ObjectRow]) -> list[str]:
    """The rows as aligned text: id, name, shape, material, shadow, triangles, bounds."""
    table = [("id", "name", "shape", "material", "shadow", "triangles", "bounds")]
    for r in rows:
        table.append((str(r.id), one_line(r.name) or "-", r.shape, shown(r.material), r.shadow,
                      "-" if r.triangles is None else str(r.triangles), _box(r.bounds)))
    widths = [min(24, max(len(row[k]) for row in table)) for k in range(6)]
    lines = []
    for row in table:
        cells = [row[0].rjust(widths[0])] + [c.ljust(w) for c, w in zip(row[1:5], widths[1:5])]
        lines.append("  ".join(cells + [row[5].rjust(widths[5]), row[6]]))
    return lines


def _box(bounds) -> str:
    if bounds is None:
        return "unbounded"
    box = np.array(bounds, dtype=float)
    box[np.abs(box) <= 1e-12 * np.abs(box).max()] = 0.0          # rounding noise of a rotation, and -0
    lo, hi = (", ".join(f"{v:.4g}" for v in corner) for corner in box)
    return f"[{lo}] .. [{hi}]"


def warnings(scene: Scene, remarks: Remarks) -> list[Remark]:
    """Every warning about the scene, in the order of the checks above."""
    colors = list(dict.fromkeys(remarks.colors))           # a color read twice (an alias) once
    found = _limited(colors, colors[LISTED].where if len(colors) > LISTED else "",
                     ("color that looks like 0-255 values", "colors that look like 0-255 values"))
    if not scene.lights:
        found.append(Remark(remarks.lights_key, "no lights: only ambient light and emission show "
                                                "(a light is {position: [x, y, z]})"))
    if not scene.objects:
        found.append(Remark(remarks.objects_key, "no objects: the image is the background"))
    elif not _camera_sees_something(scene):
        found.append(Remark(remarks.camera, "the camera sees no object: every pixel of a signature render "
                                            "is background (is look_at toward the objects?)"))
    found += _limited(_lights_inside(scene, remarks), remarks.lights_key,
                      ("light inside a closed object", "lights inside closed objects"))
    if scene.lights:
        found += _limited(_out_of_reach(scene), remarks.objects_key,
                          ("object that no light reaches", "objects that no light reaches"))
    return found


def _limited(found: list[Remark], where: str, what: tuple[str, str]) -> list[Remark]:
    """The first LISTED of found, and one line counting the rest (`what`: singular and plural)."""
    if len(found) <= LISTED:
        return found
    n = len(found) - LISTED
    return found[:LISTED] + [Remark(where, f"{n} more {what[n != 1]} (the first {LISTED} are above)")]


def strict_error(found: list[Remark]) -> RtcliError:
    """--strict's error: the first warning, and how many more there are."""
    more = f" (and {plural(len(found) - 1, 'more warning')})" if len(found) > 1 else ""
    return RtcliError(f"{found[0].where}: {found[0].message}{more}")


# --- the camera ---
def _camera_sees_something(scene: Scene) -> bool:
    """Whether the camera sees an object: one lies wholly in view, or a primary ray through a pixel
    centre, SMALL then LARGER pixels on the image's long side, hits one (the signature render's
    test). The cheap proofs come first (boxes, then the unbounded objects such as a floor, which
    every ray is tested against anyway), so a render's check rarely traces the whole scene."""
    from rtcli.rendering import engine  # start-up: validate of a plain scene traces nothing
    s = scene.settings
    if _wholly_in_view(scene, scene.camera(s.width, s.height)):
        return True
    unbounded = np.flatnonzero(~scene.boxes.bounded)
    if len(unbounded) and _signature_hits(scene, SMALL, unbounded):
        return True
    engine.numpy_engine(scene)
    return any(_signature_hits(scene, size) for size in (SMALL, LARGER)
               if size == SMALL or max(s.width, s.height) > SMALL)


def _wholly_in_view(scene: Scene, cam) -> bool:
    """Whether a bounded object lies wholly inside the camera's view: its box on the inner side of
    the four planes through the eye and the image's edges, n . (P - E) > 0 at the box's corner
    nearest each plane. The ray from the eye through any of its points then meets it or an object
    before it. A csg is left to the rays: its box may hold nothing (an empty intersection)."""
    corners = [cam.origin, cam.origin + cam.right, cam.origin + cam.right + cam.down, cam.origin + cam.down]
    edges = [c - cam.eye for c in corners]
    centre = sum(edges) / 4
    boxes = scene.boxes
    inside = boxes.bounded.copy()
    for a, b in zip(edges, edges[1:] + edges[:1]):
        n = np.cross(a, b)
        n = n if n @ centre >= 0 else -n                     # toward the inside of the view
        with np.errstate(invalid="ignore"):                  # unbounded objects' boxes are NaN
            inside &= np.where(n > 0, boxes.lo, boxes.hi) @ n - n @ cam.eye > 0
    return any(scene.objects[k].kind != "csg" for k in np.flatnonzero(inside))


def _signature_hits(scene: Scene, size: int, objects=None) -> bool:
    """Whether a primary ray through a pixel centre of the image scaled to `size` pixels on its
    long side (never enlarged) hits an object (of `objects` when given, else any)."""
    s = scene.settings
    scale = min(1.0, size / max(s.width, s.height))
    w, h = max(1, round(s.width * scale)), max(1, round(s.height * scale))
    cam = scene.camera(w, h)
    for rows in np.array_split(np.arange(h), max(1, w * h // 16384)):         # about 16,384 rays at once
        jj, ii = np.meshgrid(rows + 0.5, np.arange(w) + 0.5, indexing="ij")
        rays = camera_rays(cam, ii.ravel(), jj.ravel(), w, h)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            if objects is None:
                hits = find_first_hit(scene, rays)
            else:
                hits = no_hits(len(rays))
                nearest_over(scene, objects, rays, 0.0, hits)
        if np.isfinite(hits.t).any():
            return True
    return False


# --- lights inside objects ---
def _lights_inside(scene: Scene, remarks: Remarks) -> list[Remark]:
    """A light inside a bounded solid (a span of the line through it holds t = 0) whose material
    casts full shadows: its feelers to every point outside are blocked."""
    boxes, found = scene.boxes, []
    for k, light in enumerate(scene.lights):
        p = light.position
        near = np.flatnonzero(boxes.bounded & np.all(boxes.lo <= p, axis=1) & np.all(p <= boxes.hi, axis=1))
        for i in near:
            o = scene.objects[i]
            if o.shape.solid and scene.materials.materials[o.material].shadow is True and _inside(o, p):
                found.append(Remark(remarks.lights[k], f"the light is inside object {o.id} ({_named(o)}), "
                                                       "which casts full shadows: it lights nothing outside it"))
    return found


def _inside(o, p: np.ndarray) -> bool:
    t = o.world_from_object
    origin, direction = (p, PROBE) if t is None else (t.m_inv[:3, :3] @ p + t.m_inv[:3, 3], t.m_inv[:3, :3] @ PROBE)
    t_in, _, t_out, _ = o.shape.spans_of(origin.reshape(3, 1), direction.reshape(3, 1))
    return bool(np.any((t_in < 0) & (t_out > 0)))


def _named(o) -> str:
    return f"{shown(o.name)}, a {o.kind}" if o.name else f"a {o.kind}"


# --- objects out of every light's reach ---
def _out_of_reach(scene: Scene) -> list[Remark]:
    """Bounded objects without emission that no light reaches (the rule in the module docstring)."""
    boxes, table = scene.boxes, scene.materials
    reached = ~boxes.bounded.copy()
    lo, hi = np.nan_to_num(boxes.lo), np.nan_to_num(boxes.hi)
    for light in scene.lights:
        reached |= _reaches(light, lo, hi)
    rows = object_materials(scene.objects)
    reached |= table.emission[rows].max(axis=1) > 0
    return [Remark(scene.objects[i].where, "no light reaches it: each light's attenuated intensity at its box "
                                           "is below 1/255, or a spot light's cone misses it")
            for i in np.flatnonzero(~reached)]


def _reaches(light, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per box (N, 3 corners lo and hi): whether the light may give it 1/255 or more."""
    p = light.position
    spread = 0.0 if light.area_u is None else (np.linalg.norm(light.area_u) + np.linalg.norm(light.area_v)) / 2
    r = np.maximum(np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0), axis=1) - spread, 0.0)
    c0, c1, c2 = light.attenuation
    with np.errstate(divide="ignore"):                 # c0 = 0 at r = 0: infinitely bright
        bright = light.color.max() / (c0 + c1 * r + c2 * r * r) >= DARK
    if light.spot_direction is None:
        return bright
    centre, radius = (lo + hi) / 2, np.linalg.norm(hi - lo, axis=1) / 2 + spread
    v = centre - p
    distance = np.linalg.norm(v, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        off_axis = np.arccos(np.clip(v @ light.spot_direction / distance, -1.0, 1.0))
        seen = np.arcsin(np.clip(radius / distance, 0.0, 1.0))
    in_cone = (distance <= radius) | (off_axis - seen <= np.arccos(light.spot_cos))
    return bright & in_cone
