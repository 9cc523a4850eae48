"""Experiment: the Whitted integrator compiled per ray (numba), for issue-5 decisions.

Not used by rtcli. It renders scenes made only of untransformed spheres and one
checkered floor plane y = 0 (such as bench/whitted.yaml) with point lights,
Phong, shadow feelers, mirror and refracted rays (an explicit stack instead of
recursion), one thread per image row (numba prange), and writes a PNG. Its
pixels match `rtcli render` exactly on whitted.yaml, so it measures what a
compiled path would gain:

    python bench/compiled_whitted.py bench/whitted.yaml 1920 1080 out.png
    rtcli compare out.png rtcli.png                 # 0 bad pixels

The math is written out in scalars: small arrays allocated per ray inside the
kernel made it 2.5x slower. Material rows: ka(3) kd(3) ks(3) n shadow kr kt ior.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from numba import njit, prange
from PIL import Image

from rtcli.build import load_scene
from rtcli.shapes.sphere import Sphere


@njit(cache=True)
def sphere_t(ox, oy, oz, dx, dy, dz, s, tmax):
    """First root in (0, tmax) of the sphere s = (cx, cy, cz, r), with sphere_roots' arithmetic."""
    Sx, Sy, Sz = ox - s[0], oy - s[1], oz - s[2]
    A = dx * dx + dy * dy + dz * dz
    B = Sx * dx + Sy * dy + Sz * dz
    C = Sx * Sx + Sy * Sy + Sz * Sz - s[3] * s[3]
    disc = B * B - A * C
    if disc < 0:
        return np.inf
    q = -B - math.copysign(math.sqrt(disc), B)
    t1, t2 = q / A, C / q
    tn, tf = min(t1, t2), max(t1, t2)
    t = tn if tn > 0 else tf
    return t if 0 < t < tmax else np.inf


@njit(cache=True)
def hit(ox, oy, oz, dx, dy, dz, sph, pl, tmax):
    """(t, k): the nearest sphere k, k = len(sph) for the floor y = pl[1], or -1."""
    best, which = tmax, -1
    for k in range(sph.shape[0]):
        t = sphere_t(ox, oy, oz, dx, dy, dz, sph[k], best)
        if t < best:
            best, which = t, k
    # plane y = pl[1] normal +y
    if dy != 0:
        t = (pl[1] - oy) / dy
        if 0 < t < best:
            best, which = t, sph.shape[0]
    return best, which


@njit(cache=True)
def trace(ox, oy, oz, dx, dy, dz, sph, pl, mat, lights, amb, bg, maxd, eps):
    """Color along one primary ray; pending rays wait on a stack of (origin, dir, weight rgb, depth)."""
    stack = np.empty((64, 10))
    stack[0] = (ox, oy, oz, dx, dy, dz, 1.0, 1.0, 1.0, 1.0)
    top, cr, cg, cb = 1, 0.0, 0.0, 0.0
    nS = sph.shape[0]
    while top > 0:
        top -= 1
        ox, oy, oz, dx, dy, dz, wr, wg, wb, depth = stack[top]
        t, k = hit(ox, oy, oz, dx, dy, dz, sph, pl, np.inf)
        if k < 0:
            cr += wr * bg[0]; cg += wg * bg[1]; cb += wb * bg[2]
            continue
        px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
        if k < nS:
            nx, ny, nz = (px - sph[k, 0]) / sph[k, 3], (py - sph[k, 1]) / sph[k, 3], (pz - sph[k, 2]) / sph[k, 3]
        else:
            nx, ny, nz = 0.0, 1.0, 0.0
        dl = math.sqrt(dx * dx + dy * dy + dz * dz)
        Dx, Dy, Dz = dx / dl, dy / dl, dz / dl
        entering = Dx * nx + Dy * ny + Dz * nz < 0
        if not entering:
            nx, ny, nz = -nx, -ny, -nz
        m = mat[k]
        T0, T1, T2 = 1.0, 1.0, 1.0
        if k == nS:  # checker
            c = math.floor(px + 1e-6) + math.floor(py + 1e-6) + math.floor(pz + 1e-6)
            if c % 2 == 0:
                T0, T1, T2 = pl[2], pl[3], pl[4]
            else:
                T0, T1, T2 = pl[5], pl[6], pl[7]
        lr = m[0] * amb[0] * T0; lg = m[1] * amb[1] * T1; lb = m[2] * amb[2] * T2
        Vx, Vy, Vz = -Dx, -Dy, -Dz
        NV = nx * Vx + ny * Vy + nz * Vz
        sx, sy, sz = px + eps * nx, py + eps * ny, pz + eps * nz
        for li in range(lights.shape[0]):
            Lx, Ly, Lz = lights[li, 0] - px, lights[li, 1] - py, lights[li, 2] - pz
            r = math.sqrt(Lx * Lx + Ly * Ly + Lz * Lz)
            Lx, Ly, Lz = Lx / r, Ly / r, Lz / r
            NL = nx * Lx + ny * Ly + nz * Lz
            if NL <= 0:
                continue
            fx, fy, fz = lights[li, 0] - sx, lights[li, 1] - sy, lights[li, 2] - sz
            # shadow: any caster in (0,1)
            blocked = False
            for j in range(nS):
                if mat[j, 10] != 0 and sphere_t(sx, sy, sz, fx, fy, fz, sph[j], 1.0) < 1.0:
                    blocked = True
                    break
            if blocked:
                continue
            RV = 2 * NL * NV - (Lx * Vx + Ly * Vy + Lz * Vz)
            spec = max(RV, 0.0) ** m[9]
            lr += lights[li, 3] * (m[3] * T0 * NL + m[6] * spec)
            lg += lights[li, 4] * (m[4] * T1 * NL + m[7] * spec)
            lb += lights[li, 5] * (m[5] * T2 * NL + m[8] * spec)
        cr += wr * lr; cg += wg * lg; cb += wb * lb
        if depth >= maxd:
            continue
        kr, kt, ior = m[11], m[12], m[13]
        if kr > 0 and top < 63:
            dn = Dx * nx + Dy * ny + Dz * nz
            stack[top] = (px + eps * nx, py + eps * ny, pz + eps * nz, Dx - 2 * dn * nx, Dy - 2 * dn * ny,
                          Dz - 2 * dn * nz, wr * kr, wg * kr, wb * kr, depth + 1.0)
            top += 1
        if kt > 0 and top < 63:
            eta = 1.0 / ior if entering else ior
            ci = -(Dx * nx + Dy * ny + Dz * nz)
            kk = 1 - eta * eta * (1 - ci * ci)
            if kk >= 0:
                ct = math.sqrt(kk)
                tx, ty, tz = eta * Dx + (eta * ci - ct) * nx, eta * Dy + (eta * ci - ct) * ny, eta * Dz + (eta * ci - ct) * nz
                stack[top] = (px - eps * nx, py - eps * ny, pz - eps * nz, tx, ty, tz, wr * kt, wg * kt, wb * kt, depth + 1.0)
                top += 1
    return cr, cg, cb


@njit(cache=True, parallel=True)
def render(W, H, eye, origin, right, down, sph, pl, mat, lights, amb, bg, maxd, eps):
    """The float image, rows spread over threads; pixel centres as rtcli's fov camera."""
    img = np.empty((H, W, 3))
    for j in prange(H):
        for i in range(W):
            x, y = (i + 0.5) / W, (j + 0.5) / H
            px = origin[0] + x * right[0] + y * down[0]
            py = origin[1] + x * right[1] + y * down[1]
            pz = origin[2] + x * right[2] + y * down[2]
            c = trace(eye[0], eye[1], eye[2], px - eye[0], py - eye[1], pz - eye[2], sph, pl, mat, lights, amb, bg, maxd, eps)
            img[j, i, 0], img[j, i, 1], img[j, i, 2] = c
    return img


def main(path: str, W: int, H: int, out: str) -> None:
    start = time.perf_counter()
    scene = load_scene(path)
    cam = scene.camera(W, H)
    balls = [o for o in scene.objects if isinstance(o.shape, Sphere)]
    floor = next(o for o in scene.objects if not isinstance(o.shape, Sphere))
    order, T = balls + [floor], scene.materials
    tex = T.materials[floor.material].texture
    sph = np.array([[*o.shape.center, o.shape.radius] for o in balls])
    pl = np.array([0.0, 0.0, *tex.color1, *tex.color2])           # floor at y = pl[1]; checker colors
    mat = np.array([[*T.ka[o.material], *T.kd[o.material], *T.ks[o.material], T.n[o.material],
                     float(T.shadow[o.material]), T.kr[o.material].max(), T.kt[o.material].max(), T.ior[o.material]]
                    for o in order])
    lights = np.array([[*light.position, *light.color] for light in scene.lights])
    img = render(W, H, cam.eye, cam.origin, cam.right, cam.down, sph, pl, mat, lights, scene.ambient,
                 scene.background, scene.settings.max_depth, scene.offset)
    Image.fromarray(np.rint(np.clip(img, 0, 1) * 255).astype(np.uint8)).save(out)
    print(f"{time.perf_counter() - start:.2f} s after imports", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4])
