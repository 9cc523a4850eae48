"""The big bench scenes, generated into a cache folder (too big to commit), the same bytes each time.

    python bench/big_scenes.py [FOLDER]        (default: bench/.cache; returns at once when present)

- million: 1,000,000 spheres in a ball of radius 50, radii 0.25-0.6, seed 7, as rtcli YAML
  (one sphere a line) and POV-Ray SDL, framed alike (POV-Ray's `angle` is horizontal:
  2 atan(tan(20 deg) 4/3) = 51.78 deg frames what rtcli's vertical fov 40 frames).
- torus1m: a displaced torus of 1,000,000 triangles (1000 x 500 quads) over a floor, as an OBJ
  file with rtcli YAML and POV-Ray SDL (a mesh2) that read the same vertices.
"""

from __future__ import annotations

import os
import random
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
CACHE = os.path.join(HERE, ".cache")
RINGS, SIDES = 1000, 500                        # torus1m: quads around and across the tube


def million(folder: str, n: int = 1_000_000) -> None:
    rnd, pts = random.Random(7), []
    for _ in range(n):
        while True:                             # points in a ball of radius 50, radii 0.25-0.6
            x, y, z = (rnd.uniform(-50, 50) for _ in range(3))
            if x * x + y * y + z * z <= 2500:
                break
        pts.append((round(x, 1), round(y, 1), round(z, 1), round(rnd.uniform(0.25, 0.6), 2)))
    with open(os.path.join(folder, "million.yaml"), "w") as f:
        f.write("version: 1\nimage: {width: 640, height: 480}\n"
                "camera: {eye: [0, 30, 160], look_at: [0, 0, 0], fov: 40}\n"
                "lights: [{position: [100, 150, 200], color: [1, 1, 1]}]\nobjects:\n")
        f.writelines(f"  - {{sphere: {{center: [{x}, {y}, {z}], radius: {r}}}}}\n" for x, y, z, r in pts)
    with open(os.path.join(folder, "million.pov"), "w") as f:
        f.write('#version 3.7;\nglobal_settings { assumed_gamma 1.0 ambient_light rgb 1 }\nbackground { rgb 0 }\n'
                'camera { location <0, 30, 160> look_at <0, 0, 0> angle 51.78 right -x*4/3 }\n'
                'light_source { <100, 150, 200> color rgb 1 }\n'
                '#declare M = texture { pigment { rgb 0.8 } finish { ambient 0.1 diffuse 1 } }\n')
        f.writelines(f"sphere {{ <{x}, {y}, {z}>, {r} texture {{ M }} }}\n" for x, y, z, r in pts)


def torus_mesh() -> tuple[np.ndarray, np.ndarray]:
    """(vertices (RINGS * SIDES, 3), faces (2 * RINGS * SIDES, 3) counted from 0): a torus of radii
    2 and 0.7 around +y, its tube displaced by a ripple, standing on y = 0."""
    u = np.arange(RINGS) * 2 * np.pi / RINGS
    v = np.arange(SIDES) * 2 * np.pi / SIDES
    uu, vv = np.meshgrid(u, v, indexing="ij")
    tube = 0.7 * (1 + 0.08 * np.sin(12 * uu) * np.sin(7 * vv))
    ring = 2 + tube * np.cos(vv)
    verts = np.stack([ring * np.cos(uu), tube * np.sin(vv) + 0.9, ring * np.sin(uu)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(RINGS), np.arange(SIDES), indexing="ij")
    a, b = i * SIDES + j, ((i + 1) % RINGS) * SIDES + j
    c, d = ((i + 1) % RINGS) * SIDES + (j + 1) % SIDES, i * SIDES + (j + 1) % SIDES
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return np.round(verts, 5), faces


def torus1m(folder: str) -> None:
    verts, faces = torus_mesh()
    with open(os.path.join(folder, "torus1m.obj"), "w") as f:
        f.write(f"# displaced torus, {len(verts)} vertices, {len(faces)} triangles (bench/big_scenes.py)\n")
        f.write("".join(f"v {x:.5f} {y:.5f} {z:.5f}\n" for x, y, z in verts))
        f.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    with open(os.path.join(folder, "torus1m.yaml"), "w") as f:
        f.write("# torus1m.obj over a floor; the same scene as torus1m.pov (POV-Ray is left-handed: x mirrored)\n"
                "version: 1\nimage: {width: 640, height: 480}\n"
                "camera: {eye: [0, 4.2, -7.0], look_at: [0, 1.0, 0], fov: 38.553}\n"
                "background: [0.60, 0.70, 0.85]\nambient: [1, 1, 1]\nrender: {max_depth: 5, specular: phong}\n"
                "lights:\n  - {position: [6, 10, -7], color: [1, 1, 1]}\nobjects:\n"
                "  - name: floor\n    plane: {point: [0, 0, 0], normal: [0, 1, 0]}\n"
                "    material: {ambient: 0.055, diffuse: 0.44, specular: 0}\n"
                "  - name: torus\n    mesh: {file: torus1m.obj, smooth: false}\n"
                "    material: {ambient: [0.085, 0.055, 0.02], diffuse: [0.595, 0.385, 0.14], specular: 0.6, "
                "shininess: 40}\n    transform:\n      - {scale: [-1, 1, 1]}\n")
    with open(os.path.join(folder, "torus1m.pov"), "w") as f:
        f.write("#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 5 }\n"
                "camera { perspective location <0, 4.2, -7.0> look_at <0, 1.0, 0> right x*image_width/image_height "
                "up y angle 50 }\nbackground { color rgb <0.60, 0.70, 0.85> }\n"
                "light_source { <-6, 10, -7> color rgb <1, 1, 1> }\n"
                "plane { y, 0 pigment { color rgb <0.55, 0.55, 0.55> } finish { ambient 0.1 diffuse 0.8 } }\n"
                f"mesh2 {{\n vertex_vectors {{ {len(verts)},\n")
        f.write(",\n".join(f"  <{x:.5f}, {y:.5f}, {z:.5f}>" for x, y, z in verts))
        f.write(f"\n }}\n face_indices {{ {len(faces)},\n")
        f.write(",\n".join(f"  <{a}, {b}, {c}>" for a, b, c in faces))
        f.write("\n }\n pigment { color rgb <0.85, 0.55, 0.2> }\n"
                " finish { ambient 0.1 diffuse 0.7 phong 0.6 phong_size 40 }\n}\n")


def ensure(folder: str = CACHE) -> str:
    """The folder, with the big scenes written into it unless they are there already."""
    os.makedirs(folder, exist_ok=True)
    if not os.path.exists(os.path.join(folder, "million.pov")):
        million(folder)
    if not os.path.exists(os.path.join(folder, "torus1m.pov")):
        torus1m(folder)
    return folder


if __name__ == "__main__":
    print(ensure(sys.argv[1] if len(sys.argv) > 1 else CACHE))
