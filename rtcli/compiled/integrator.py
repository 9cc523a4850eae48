"""rayTrace() of notes 000 11.7 compiled per ray (numba): the fast path for the scenes pack.py accepts.

The numpy core (trace.py, shade.py, intersect.py) is the reference; this is the
same integrator written for one ray, so no array is built per bounce:

    radiance(ray) = background                                   on a miss
                  = local(p) + kr radiance(mirror ray) + kt radiance(refracted ray)

with the local term of shade.py (emission + ka Ia T + per light not in shadow
with N.L > 0: att(r) I (kd T (N.L) + ks spec)). Every sum and product is taken
in the numpy code's order, so both paths give the same pixels.
"""

from __future__ import annotations

import math

import numpy as np

from rtcli.compiled.pack import IMAGE, KIND, MESH, NO_TEXTURE, NRM, SMOOTH, TRIANGLE, XF
from rtcli.compiled.query import object_ray, scene_hit
from rtcli.compiled.shapes import apply, entry, inline, interpolated, jit, normal
from rtcli.compiled.uv import image, uv

SHADOW, REFLECTED, REFRACTED = 1, 2, 3                   # counters, as stats.Stats (primary: the caller's)


@inline
def surface(g, k, prim, t, ox, oy, oz, dx, dy, dz):
    """Unit outward shading and geometric normals at the hit, and the object-space hit point
    (intersect.surface: smooth triangles interpolate their corner normals)."""
    row, kind, transformed = g.objects[k], g.ints[k, KIND], g.ints[k, XF]
    qx, qy, qz, ex, ey, ez = object_ray(row, transformed, ox, oy, oz, dx, dy, dz)
    px, py, pz = qx + t * ex, qy + t * ey, qz + t * ez
    tri, smooth = row, False
    if kind == MESH:
        tri, smooth = g.pool[prim], g.ints[k, SMOOTH] != 0
        gx, gy, gz = tri[9], tri[10], tri[11]
    else:
        smooth = kind == TRIANGLE and row[21] != 0
        gx, gy, gz = normal(kind, row, px, py, pz, prim)
    nx, ny, nz = gx, gy, gz
    if smooth:
        nx, ny, nz = interpolated(tri, px, py, pz)
        if not math.sqrt(nx * nx + ny * ny + nz * nz) > 0:
            nx, ny, nz = gx, gy, gz                                   # corner normals cancel: the face's
    if transformed:
        nx, ny, nz = apply(row, NRM, nx, ny, nz, 0)
        gx, gy, gz = apply(row, NRM, gx, gy, gz, 0)
    length, glength = math.sqrt(nx * nx + ny * ny + nz * nz), math.sqrt(gx * gx + gy * gy + gz * gz)
    return nx / length, ny / length, nz / length, gx / glength, gy / glength, gz / glength, px, py, pz


@inline
def texture(g, s, m, k, prim, px, py, pz):
    """T at the object-space point: 1 without a texture, else the checker's color
    (textures.Checker) or the picture's at the shape's (u, v) (textures.ImageTexture)."""
    c = s.texture[m]
    if c[0] == NO_TEXTURE:
        return 1.0, 1.0, 1.0
    if c[0] == IMAGE:
        kind, row = g.ints[k, KIND], g.objects[k]
        u, v = uv(kind, row, g.pool[prim] if kind == MESH else row, prim, px, py, pz)
        return image(s.texels, c, u, v)
    cells = np.floor(px * c[1] + 1e-6) + np.floor(py * c[1] + 1e-6) + np.floor(pz * c[1] + 1e-6)
    j = 2 if cells % 2.0 == 0 else 5                                # an integer, as a float: even or odd
    return c[j], c[j + 1], c[j + 2]


@jit
def mix(x):
    """splitmix64's finalizer (jitter._mix)."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


@jit
def uniform(s, x, y, z, cell, axis):
    """jitter.uniform(x, y, z, cell, axis): a number in [0, 1) hashed from the floats' bits and two ints."""
    golden = np.uint64(0x9E3779B97F4A7C15)
    h = golden
    for key in (x, y, z):
        s.word[0] = key
        h = mix(h ^ s.bits[0]) + golden
    h = mix(h ^ np.uint64(cell)) + golden
    h = mix(h ^ np.uint64(axis)) + golden
    return np.float64(mix(h) >> np.uint64(11)) * (1.0 / (1 << 53))


@inline
def light_sample(g, s, m, T, light, points, qx, qy, qz, px, py, pz, nx, ny, nz, sx, sy, sz, Vx, Vy, Vz, NV,
                 cr, cg, cb, counts, stack):
    """One light position q's term, added to (cr, cg, cb): diffuse and specular if N.L > 0 and
    the feeler from s (the hit point stepped off the surface) to q meets no shadow caster."""
    lx, ly, lz = qx - px, qy - py, qz - pz
    r = math.sqrt(lx * lx + ly * ly + lz * lz)
    Lx, Ly, Lz = lx / r, ly / r, lz / r
    NL = nx * Lx + ny * Ly + nz * Lz
    if not NL > 0:                                                    # no contribution (004, case 2)
        return cr, cg, cb
    counts[SHADOW] += 1
    if scene_hit(g, sx, sy, sz, qx - sx, qy - sy, qz - sz, 0.0, 1.0, True, stack)[1] >= 0:
        return cr, cg, cb
    spot = 1.0
    if light[14] != 0:
        cos = -(Lx * light[9] + Ly * light[10] + Lz * light[11])
        spot = max(cos, 0.0) ** light[13] if cos >= light[12] else 0.0
    weight = 1.0 / (light[6] + light[7] * r + light[8] * r * r) * spot / points
    wNL = weight * NL
    cr += wNL * light[3] * (s.kd[m, 0] * T[0])
    cg += wNL * light[4] * (s.kd[m, 1] * T[1])
    cb += wNL * light[5] * (s.kd[m, 2] * T[2])
    if s.shiny[m]:
        if s.blinn:
            Hx, Hy, Hz = Lx + Vx, Ly + Vy, Lz + Vz
            cos = (nx * Hx + ny * Hy + nz * Hz) / math.sqrt(Hx * Hx + Hy * Hy + Hz * Hz)
        else:
            cos = 2 * NL * NV - (Lx * Vx + Ly * Vy + Lz * Vz)
        w = weight * max(cos, 0.0) ** s.shininess[m]
        cr += w * light[3] * s.ks[m, 0]
        cg += w * light[4] * s.ks[m, 1]
        cb += w * light[5] * s.ks[m, 2]
    return cr, cg, cb


@inline
def local(g, s, m, T, px, py, pz, nx, ny, nz, gx, gy, gz, Vx, Vy, Vz, counts, stack):
    """shade.local for one hit: emission, ambient and the lights that see it."""
    cr = s.emission[m, 0] + s.ka[m, 0] * s.ambient[0] * T[0]
    cg = s.emission[m, 1] + s.ka[m, 1] * s.ambient[1] * T[1]
    cb = s.emission[m, 2] + s.ka[m, 2] * s.ambient[2] * T[2]
    NV = nx * Vx + ny * Vy + nz * Vz
    eps = s.offset
    sx, sy, sz = px + eps * gx, py + eps * gy, pz + eps * gz          # feelers leave from the lit side
    for li in range(len(s.lights)):
        light = s.lights[li]
        n = int(light[21])
        points = n * n if n > 0 else 1                                # area lights: n x n jittered points
        for cell in range(points):
            if n > 0:
                fu = (cell // n + uniform(s, px, py, pz, cell, 0)) / n - 0.5
                fv = (cell % n + uniform(s, px, py, pz, cell, 1)) / n - 0.5
                qx = light[0] + fu * light[15] + fv * light[18]
                qy = light[1] + fu * light[16] + fv * light[19]
                qz = light[2] + fu * light[17] + fv * light[20]
            else:
                qx, qy, qz = light[0], light[1], light[2]
            cr, cg, cb = light_sample(g, s, m, T, light, points, qx, qy, qz, px, py, pz, nx, ny, nz, sx, sy, sz,
                                      Vx, Vy, Vz, NV, cr, cg, cb, counts, stack)
    return cr, cg, cb


@inline
def shade_local(g, s, ray, f, counts, stack):
    """First hit and local term of one ray: (hit?, color); on a hit, f holds the frame of the
    secondary rays: color, p, facing n, unit D, entering, material, stage 0, facing geometric n."""
    ox, oy, oz, dx, dy, dz = ray
    t, k, prim = scene_hit(g, ox, oy, oz, dx, dy, dz, 0.0, np.inf, False, stack)
    if k < 0:
        return False, s.background[0], s.background[1], s.background[2]
    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
    nx, ny, nz, gx, gy, gz, qx, qy, qz = surface(g, k, prim, t, ox, oy, oz, dx, dy, dz)
    entering = dx * gx + dy * gy + dz * gz < 0
    if not entering:                                                  # face the incoming ray
        nx, ny, nz, gx, gy, gz = -nx, -ny, -nz, -gx, -gy, -gz
    if dx * nx + dy * ny + dz * nz > 0:                               # a shading normal turned away
        nx, ny, nz = gx, gy, gz
    m = s.material[k]
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    Dx, Dy, Dz = dx / length, dy / length, dz / length
    T = texture(g, s, m, k, prim, qx, qy, qz)
    cr, cg, cb = local(g, s, m, T, px, py, pz, nx, ny, nz, gx, gy, gz, -Dx, -Dy, -Dz, counts, stack)
    f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8] = cr, cg, cb, px, py, pz, nx, ny, nz
    f[9], f[10], f[11], f[12], f[13], f[14] = Dx, Dy, Dz, 1.0 if entering else 0.0, m, 0
    f[15], f[16], f[17] = gx, gy, gz
    return True, cr, cg, cb


@inline
def next_ray(s, f, counts):
    """The frame's next secondary ray (trace.shade): the mirror ray at stage 0, the refracted
    ray at stage 1 (none past the critical angle); (False, _) when none is left."""
    m = int(f[13])
    px, py, pz, nx, ny, nz, Dx, Dy, Dz = f[3], f[4], f[5], f[6], f[7], f[8], f[9], f[10], f[11]
    ex, ey, ez = s.offset * f[15], s.offset * f[16], s.offset * f[17]  # step off the surface
    if f[14] == 0:
        f[14] = 1
        if s.mirror[m]:
            counts[REFLECTED] += 1
            dn = 2 * (Dx * nx + Dy * ny + Dz * nz)                    # ms = d - 2 (d.n) n
            return True, (px + ex, py + ey, pz + ez, Dx - dn * nx, Dy - dn * ny, Dz - dn * nz)
    if f[14] == 1:
        f[14] = 2
        if s.clear[m]:
            ior = s.ior[m]
            eta = 1.0 / ior if f[12] else ior                         # 1 -> ior entering, ior -> 1 leaving
            cos_i = -(Dx * nx + Dy * ny + Dz * nz)
            kk = 1 - eta * eta * (1 - cos_i * cos_i)
            if not kk < 0:                                            # else total internal reflection
                counts[REFRACTED] += 1
                b = eta * cos_i - math.sqrt(max(kk, 0.0))
                tx, ty, tz = eta * Dx + b * nx, eta * Dy + b * ny, eta * Dz + b * nz
                tl = math.sqrt(tx * tx + ty * ty + tz * tz)
                return True, (px - ex, py - ey, pz - ez, tx / tl, ty / tl, tz / tl)
    return False, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@jit
def radiance(g, s, ray, counts, frames, stack):
    """The color seen along one primary ray: local + kr radiance(mirror) + kt radiance(refracted),
    depth first with frames[L] the pending hit at depth L + 1 instead of recursion."""
    L = 0
    while True:
        found, cr, cg, cb = shade_local(g, s, ray, frames[L], counts, stack)
        more = False
        if found and L + 1 < s.max_depth:
            more, ray = next_ray(s, frames[L], counts)
        while not more and L > 0:                                     # hand the color to the parent
            L -= 1
            f, m = frames[L], int(frames[L, 13])
            k = s.kr[m] if f[14] == 1 else s.kt[m]
            f[0], f[1], f[2] = f[0] + k[0] * cr, f[1] + k[1] * cg, f[2] + k[2] * cb
            more, ray = next_ray(s, f, counts)
            cr, cg, cb = f[0], f[1], f[2]
        if not more:
            return cr, cg, cb
        L += 1


@entry
def trace_camera(g, s, eye, origin, right, down, x, y, nc, nr, counts, stack):
    """(n, 3) colors of the primary rays through the pixel coordinates (x, y) (n,) of a
    camera.Camera: from the eye through origin + (x / nc) right + (y / nr) down."""
    n = len(x)
    out = np.empty((n, 3))
    frames = np.empty((max(s.max_depth, 1), 18))
    for i in range(n):
        a, b = x[i] / nc, y[i] / nr
        px, py, pz = (origin[0] + a * right[0] + b * down[0], origin[1] + a * right[1] + b * down[1],
                      origin[2] + a * right[2] + b * down[2])
        ray = (eye[0], eye[1], eye[2], px - eye[0], py - eye[1], pz - eye[2])
        out[i] = radiance(g, s, ray, counts, frames, stack)
    return out
