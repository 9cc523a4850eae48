"""The reference scenes as Mitsuba 3 scene dictionaries, made from the same YAML files.

Each scene's camera, lights, spheres, planes and meshes are read from bench/NAME.yaml
and written as Mitsuba's plugins: a `perspective` sensor with `fov_axis: "y"` (rtcli's
`fov` is vertical), an `independent` sampler at 1 sample, a box-filtered film, `point`
emitters, `sphere`, `obj` (flat: `face_normals`) and, for the planes, a large
`rectangle`. Which integrator:

- torus100k, spheres1k: `direct` with one emitter sample and no BSDF sample: a camera
  ray and one shadow ray per hit, rtcli's work on these scenes (spheres1k's 261
  mirror spheres also send rtcli's reflected rays, about 10% more rays);
- whitted: `path` with max_depth 5, a smooth `conductor` for the mirror and a
  `dielectric` for the glass: similar work, not the same (a path tracer at one sample
  per pixel is not a Whitted ray tracer);
- quadrics: not written (Mitsuba has no cone or capped cylinder);
- torus1m (bench/big_scenes.py): as torus100k, with a million triangles;
- million: written (as spheres1k, each sphere a `sphere` plugin) but not timed: Mitsuba's
  load_dict of a million plugins had not finished after 15 minutes (83 s of CPU, 4.8 GB).

Point lights in Mitsuba fall off with 1 / r^2 and rtcli's (without attenuation) do not;
each emitter's intensity is scaled by its squared distance to the camera's target, so
the pictures are alike in brightness. The time, not the picture, is what is compared.

    python bench/mitsuba_scenes.py NAME VARIANT WIDTH HEIGHT OUT.png   # one render, as bench/run.py times it
"""

from __future__ import annotations

import os
import sys

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = ("whitted", "spheres1k", "torus100k", "torus1m")     # those written for Mitsuba
SAME_WORK = ("spheres1k", "torus100k", "torus1m")              # the same rays as rtcli's, give or take mirrors
BIG = ("million", "torus1m")                            # generated into a cache folder (bench/big_scenes.py)


def _vec(v) -> list[float]:
    return [float(x) for x in np.broadcast_to(np.asarray(v, dtype=float), (3,))]


def _material(m: dict, named: dict, whitted: bool) -> dict:
    m = named.get(m, m) if isinstance(m, str) else m
    if whitted and m.get("transmission"):
        return {"type": "dielectric", "int_ior": float(m.get("ior", 1.5)), "ext_ior": 1.0}
    if whitted and m.get("reflection"):
        return {"type": "conductor", "material": "none",
                "specular_reflectance": {"type": "rgb", "value": _vec(m["reflection"])}}
    texture = m.get("texture", {}).get("checker")
    if texture:
        return {"type": "diffuse", "reflectance": {
            "type": "checkerboard", "color0": {"type": "rgb", "value": _vec(texture["colors"][0])},
            "color1": {"type": "rgb", "value": _vec(texture["colors"][1])}}}
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": _vec(m.get("diffuse", 0.8))}}


def scene_dict(name: str, width: int, height: int, mi) -> dict:
    """Mitsuba's dict of bench/NAME.yaml at width x height (`mi`: the mitsuba module, variant set)."""
    if name not in SCENES + ("million",):
        raise ValueError(f"{name} has no Mitsuba form (Mitsuba has {', '.join(SCENES)})")
    folder = _folder(name)
    with open(os.path.join(folder, f"{name}.yaml")) as f:
        doc = yaml.load(f, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    T = mi.ScalarTransform4f
    cam = doc["camera"]
    target = _vec(cam["look_at"])
    whitted = name == "whitted"
    out = {
        "type": "scene",
        "integrator": ({"type": "path", "max_depth": 5} if whitted
                       else {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0}),
        "sensor": {
            "type": "perspective", "fov": float(cam["fov"]), "fov_axis": "y",
            "to_world": T().look_at(origin=_vec(cam["eye"]), target=target, up=_vec(cam.get("up", [0, 1, 0]))),
            "sampler": {"type": "independent", "sample_count": 1},
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
        },
    }
    if whitted:                         # the sky, seen by the path tracer's rays that escape
        out["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": _vec(doc.get("background", 0))}}
    for k, light in enumerate(doc.get("lights", [])):
        r2 = float(np.sum((np.array(_vec(light["position"])) - target) ** 2))
        out[f"light{k}"] = {"type": "point", "position": _vec(light["position"]),
                            "intensity": {"type": "rgb", "value": [c * r2 for c in _vec(light.get("color", 1))]}}
    named = doc.get("materials", {})
    for k, obj in enumerate(doc["objects"]):
        bsdf = _material(obj.get("material", {}), named, whitted)
        if "sphere" in obj:
            s = obj["sphere"]
            shape = {"type": "sphere", "center": _vec(s.get("center", 0)), "radius": float(s.get("radius", 1))}
        elif "plane" in obj:
            p = obj["plane"]
            size = 1000.0
            to_world = T().translate(_vec(p.get("point", 0))) @ T().rotate([1, 0, 0], -90) @ T().scale(size)
            shape = {"type": "rectangle", "to_world": to_world}
            if bsdf["reflectance"].get("type") == "checkerboard":   # one check a unit, as rtcli's size 1
                bsdf["reflectance"]["to_uv"] = mi.ScalarTransform4f().scale([size, size, 1])
        elif "mesh" in obj:
            m = obj["mesh"]
            shape = {"type": "obj", "filename": os.path.join(folder, m["file"]), "face_normals": not m.get("smooth")}
            scale = [step["scale"] for step in obj.get("transform", []) if "scale" in step]
            if scale:
                shape["to_world"] = T().scale(_vec(scale[0]))
        else:
            raise ValueError(f"{name}: object {k} has a shape this script does not write for Mitsuba")
        shape["bsdf"] = bsdf
        out[f"object{k}"] = shape
    return out


def _folder(name: str) -> str:
    """Where bench/NAME.yaml is: bench/, or the big scenes' cache folder (bench/big_scenes.py)."""
    if name not in BIG:
        return HERE
    sys.path.insert(0, HERE)
    from big_scenes import ensure  # bench/ is not a package: its folder on the path first
    return ensure()


def main(argv: list[str]) -> None:
    name, variant, width, height, output = argv
    import mitsuba as mi
    mi.set_variant(variant)
    image = mi.render(mi.load_dict(scene_dict(name, int(width), int(height), mi)))
    mi.util.write_bitmap(output, image)


if __name__ == "__main__":
    main(sys.argv[1:])
