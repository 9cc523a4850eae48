"""Scene tree -> Scene: the top level, the camera, lights and settings (docs/scene-format.md).

Only the modules of rtcli/scenefile/ know YAML keys. Every key is read through
Params, so unknown keys are reported with file:line:col. The documents built here
hold plain values only: an animated scene's frame comes here with its keyframes
resolved (animation.py), and load.py reads a scene file, still or animated.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from rtcli.core import camera as cameras
from rtcli.core.elementary import cos
from rtcli.core.lights import PointLight
from rtcli.core.materials import Material, MaterialTable
from rtcli.core.objects import kind_counts
from rtcli.core.scene import Scene, Settings
from rtcli.core.vec import unit3
from rtcli.errors import SceneError, plural
from rtcli.scenefile import remarks
from rtcli.scenefile.limits import MAX_PIXELS, MAX_SIDE
from rtcli.scenefile.materials import material_from
from rtcli.scenefile.objects import ObjectBuilder
from rtcli.scenefile.params import Params, as_params
from rtcli.scenefile.transforms import transform_from
from rtcli.scenefile.values import describe


def check_image_size(width: int, height: int) -> str | None:
    """Why a width x height image is refused (see limits.MAX_PIXELS), or None."""
    if width * height <= MAX_PIXELS:
        return None
    return (f"{width}x{height} is {width * height:,} pixels, more than the {MAX_PIXELS:,} allowed "
            "(16384 x 16384; rendering keeps the whole image in memory)")


def camera_form(scene: Scene) -> str:
    """'fov', 'window' or 'screen': which of the three camera forms the scene uses."""
    forms = {cameras.from_fov: "fov", cameras.from_window: "window", cameras.from_screen: "screen"}
    return forms.get(getattr(scene.camera, "func", None), "fov")


def build_scene(docs: list) -> Scene:
    """The scene of documents whose values are all plain (an animation's frame: keyframes resolved)."""
    params = [Params(doc, "") for doc in docs]
    main = params[-1]
    main.known("version", "include", "image", "camera", "background", "ambient", "render",
               "lights", "materials", "objects", "animation")
    for p in params:
        if p.has("version") and p.raw("version") != 1:
            raise p.error("version", f"unsupported version {describe(p.raw('version'))} (this is version 1)")
        p.known("version", "include")
    named, table = {}, [Material()]
    for p in params:
        for name, mp in _materials(p):
            named[name] = len(table)
            table.append(dataclasses.replace(material_from(mp), name=name))
    builder, lights, places = ObjectBuilder(named, table, 0), [], []
    for p in params:
        for item, where, path in p.items("lights", []):
            lights.append(light_from(as_params(item, where, path, "a light mapping")))
            places.append(remarks.at(where, path))
        builder.add_all(p.items("objects", []))
    for p in params[:-1]:
        p.check_unused()
    scene = _top_level(main, builder, lights, table)
    main.check_unused()
    if (record := remarks.current()) is not None:
        _remember(record, params, places)
    return scene


def _remember(record: remarks.Remarks, params: list[Params], places: list[str]) -> None:
    """For `rtcli validate`: where the camera, the lights and the objects are written."""
    main = params[-1]
    record.camera = remarks.at(main.node.value_where.get("camera", main.where), "camera")
    record.lights = places
    for key in ("lights", "objects"):
        given = [p for p in params if p.has(key)]
        place = remarks.at(given[-1].node.value_where[key] if given else main.where, key)
        setattr(record, f"{key}_key", place)


def _materials(p: Params):
    m = p.optional("materials")
    if m is None:
        return []
    m.known(*m.node)
    return [(name, m.sub(name)) for name in m.node]


def _top_level(p: Params, builder: ObjectBuilder, lights, table) -> Scene:
    settings = Settings()
    img = p.optional("image")
    if img is not None:
        settings.width = img.integer("width", 640, 1, MAX_SIDE)
        settings.height = img.integer("height", 480, 1, MAX_SIDE)
        if (why := check_image_size(settings.width, settings.height)) is not None:
            raise img.error(None, why)
        img.check_unused()
    r = p.optional("render")
    if r is not None:
        settings.max_depth = r.integer("max_depth", 5, 1, 64)
        settings.specular = r.choice("specular", ("phong", "blinn"), "phong")
        settings.samples = r.integer("samples", 1, 1, 16)
        settings.epsilon = r.number("epsilon", 1e-6, positive=True)
        settings.medium_ior = r.number("medium_ior", 1.0, positive=True)
        settings.total_internal_reflection = r.choice("total_internal_reflection", ("drop", "reflect"), "drop")
        settings.alpha = r.boolean("alpha", False)
        settings.shadow_terminator = r.choice("shadow_terminator", ("none", "offset"), "none")
        r.check_unused()
    camera, eye = camera_from(p.sub("camera"))
    check_resolvable(p, camera, settings.width, settings.height)
    return Scene(camera=camera, objects=builder.objects, materials=MaterialTable(table),
                 lights=lights, background=p.color("background", (0.0, 0.0, 0.0)),
                 ambient=p.color("ambient", (0.1, 0.1, 0.1)), settings=settings, eye=eye)


CAMERA_FORMS = {"fov": ("eye", "look_at", "up", "fov"),           # the keys of each camera form
                "window": ("eye", "look_at", "up", "focal", "window"),
                "screen": ("eye", "screen")}


def camera_from(c: Params):
    """One of the three camera forms; returns (callable (nc, nr) -> Camera, eye).

    An optional `transform:` (the steps of an object's) moves the camera: its points
    (eye, look_at, lower_left) and directions (up, horizontal, vertical)."""
    c.known("eye", "look_at", "up", "fov", "focal", "window", "screen", "transform")
    form = "screen" if c.has("screen") else "window" if c.has("window") else "fov"
    for key in c.node:
        if key in c.read and key not in CAMERA_FORMS[form] + ("transform",):
            raise SceneError(c.node.key_where[key], c.key_path(key), f"the {form} form of the camera takes "
                             f"no {key} (it takes {', '.join(CAMERA_FORMS[form])}; docs/scene-format.md, Camera)")
    moved = transform_from(c)
    point = (lambda x: x) if moved is None else moved.point
    direction = (lambda x: x) if moved is None else moved.vector
    eye = point(c.vector("eye"))
    if form == "screen":
        s = c.sub("screen")
        s.known("lower_left", "horizontal", "vertical")
        ll, h, v = point(s.vector("lower_left")), direction(s.vector("horizontal")), direction(s.vector("vertical"))
        s.check_unused()
        if np.linalg.norm(np.cross(h, v)) == 0:
            raise s.error(None, "horizontal and vertical must span a rectangle (not zero or parallel)")
        c.check_unused()
        return functools.partial(cameras.from_screen, eye, ll, h, v), eye
    look_at, up = point(c.vector("look_at")), direction(c.vector("up", (0.0, 1.0, 0.0)))
    if not np.any(look_at - eye):
        raise c.error("look_at", "must differ from eye")
    if np.linalg.norm(np.cross(look_at - eye, up)) <= 1e-9 * np.linalg.norm(look_at - eye) * np.linalg.norm(up):
        if c.has("up"):
            raise c.error("up", "must not be parallel to the view direction (look_at - eye)")
        raise c.error(None, "the default up [0, 1, 0] is parallel to the view direction; give camera.up")
    if form == "window":
        focal = c.number("focal", 1.0, positive=True)
        w = c.sub("window")
        w.known("left", "right", "top", "bottom")
        wl, wr, wt, wb = (w.number(k) for k in ("left", "right", "top", "bottom"))
        w.check_unused()
        if wl == wr or wt == wb:
            raise w.error(None, "the window must have left != right and top != bottom")
        c.check_unused()
        return functools.partial(cameras.from_window, eye, look_at, up, focal, wl, wr, wt, wb), eye
    fov = c.number("fov", 45.0)
    if not 0 < fov < 180:
        raise c.error("fov", f"must be between 0 and 180 degrees, got {fov:g}")
    c.check_unused()
    return functools.partial(cameras.from_fov, eye, look_at, up, fov), eye


def check_resolvable(p: Params, camera, width: int, height: int) -> None:
    """Refuse a camera whose pixels are finer than the rounding of its image-plane points.

    Rays go from the eye to points of the image plane, p - eye. With the eye very
    far from the origin compared with a pixel of the plane (an eye at 1e17 and a
    plane one unit away), those points round to a grid coarser than the pixels:
    neighbouring pixels would get the same ray, or rays no direction at all.
    """
    cam = camera(width, height)
    rounding = np.spacing(max(np.abs(cam.eye).max(), np.abs(cam.origin).max()))
    pixel = min(np.linalg.norm(cam.right) / width, np.linalg.norm(cam.down) / height)
    if not 4 * rounding < pixel:
        raise p.error("camera", "the eye is too far from the origin for the size of its image plane: "
                                "neighbouring pixels would get the same ray in double precision (bring the "
                                "scene nearer the origin, or make the window or fov larger)")


def light_from(p: Params) -> PointLight:
    p.known("position", "color", "attenuation", "spot", "area")
    position, color = p.vector("position"), p.color("color", (1.0, 1.0, 1.0))
    att = p.numbers("attenuation", 3, (1.0, 0.0, 0.0), "[c0, c1, c2]")
    if np.any(att < 0) or not np.any(att):
        raise p.error("attenuation", "c0, c1, c2 must be >= 0 and not all 0")
    extra = {}
    s = p.optional("spot")
    if s is not None:
        s.known("direction", "angle", "falloff")
        direction = s.vector("direction")
        if not np.any(direction):
            raise s.error("direction", "must not be the zero vector")
        angle = s.number("angle", 30.0)
        if not 0 < angle <= 180:
            raise s.error("angle", f"must be in (0, 180] degrees, got {angle:g}")
        extra.update(spot_direction=unit3(direction), spot_cos=float(cos(np.radians(angle))),
                     spot_falloff=s.number("falloff", 0.0, non_negative=True))
        s.check_unused()
    a = p.optional("area")
    if a is not None:
        a.known("u", "v", "samples")
        extra.update(area_u=a.vector("u"), area_v=a.vector("v"), area_samples=a.integer("samples", 3, 1, 16))
        a.check_unused()
    p.check_unused()
    return PointLight(position, color, att, **extra)


def summary(scene: Scene) -> str:
    """One line for `rtcli validate`."""
    s = scene.settings
    shapes = ", ".join(f"{n} {k}" for k, n in kind_counts(scene.objects).items())
    return (f"{plural(len(scene.objects), 'object')} ({shapes or 'none'}), {plural(len(scene.lights), 'light')}, "
            f"{plural(len(scene.materials) - 1, 'material')}; {s.width}x{s.height}, max_depth {s.max_depth}, "
            f"{s.specular}, samples {s.samples}")
