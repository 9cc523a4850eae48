"""rayTrace() of notes 000 11.7, one ray at a time: the compiled engine's integrator.

The numpy engine (rtcli/wavefront/trace.py) is the reference; this is the same
integrator written for one ray, so no array is built per bounce:

    radiance(ray) = background                                   on a miss
                  = local(p) + kr radiance(mirror ray) + kt radiance(refracted ray)

Every formula comes from the shared kernels: the camera ray (core/camera.py), the
shapes' normals and (u, v) (rtcli/shapes/), textures, lights and the local term
(core/textures.py, core/lights.py, core/shading.py), reflect and refract
(core/vec.py), media, Fresnel and the rays' weights (core/dielectric.py). What is
this engine's own is the order of work: a loop over depth with a stack of frames in
place of recursion (numba's recursion is slow and breaks its on-disk cache).
frames[L] holds the hit at depth L + 1 while its secondary rays are traced, and the
media of the ray that made it; its columns are named in compiled/pack.py.
"""

from __future__ import annotations

import numpy as np

from rtcli.compiled.pack import (
    BASE,
    BLOCKED,
    COLOR_SUM,
    CSG_KIND,
    ENTERING,
    FEELERS,
    KIND,
    MATERIAL_OF,
    MEDIA_COUNT,
    MEDIA_IOR,
    NG,
    PACKED_LIGHTS,
    PATH_WEIGHT,
    REFRACTED_DIR,
    SMOOTH_KINDS,
    STAGE,
    TEXTURE,
    W_REFLECT,
    W_REFRACT,
    XFORM,
    D,
    N,
    P,
)
from rtcli.compiled.query import NORMALS_ANY, UV_ANY, csg_normals, csg_uv, leaf_point, material_of, scene_hit
from rtcli.core.bvh import ANY_CASTER, NEAREST, NEAREST_CASTER
from rtcli.core.dielectric import FEELER_CROSSINGS, fresnel, indices, refracted_media, split
from rtcli.core.lights import COLOR, sample_point, toward, weight
from rtcli.core.shading import ambient, diffuse, facing, path_weight, specular, specular_cos
from rtcli.core.textures import IMAGE, NONE, texture_color
from rtcli.core.textures import KIND as TEXTURE_KIND
from rtcli.core.transform import WORLD, linear, normal_to_world, ray_to_object
from rtcli.core.vec import dot, reflect, refract, unit
from rtcli.kernels.variants import per_ray, to_int
from rtcli.shapes.triangle import terminator

SHADOW, REFLECTED, REFRACTED = 1, 2, 3                   # counters, as stats.Stats (primary: the caller's)


@per_ray(inline=True)
def surface(g, k, prim, t, ox, oy, oz, dx, dy, dz):
    """The unit outward shading and geometric normals at the hit (world space, by A^-T), and the
    object-space hit point."""
    x = g.ints[k, XFORM]
    if x >= 0:
        ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
    if g.ints[k, KIND] == CSG_KIND:
        nx, ny, nz, gx, gy, gz = csg_normals(g, prim, px, py, pz)
    else:
        nx, ny, nz, gx, gy, gz = NORMALS_ANY(g.ints[k, KIND], g.objects[k], g.pool, prim, px, py, pz)
    if x >= 0:
        nx, ny, nz = normal_to_world(g.transforms[x], 0, nx, ny, nz)
        gx, gy, gz = normal_to_world(g.transforms[x], 0, gx, gy, gz)
    nx, ny, nz = unit(nx, ny, nz)
    gx, gy, gz = unit(gx, gy, gz)
    return nx, ny, nz, gx, gy, gz, px, py, pz


@per_ray(inline=True)
def texture_at(g, s, m, k, prim, px, py, pz):
    """T at the object-space point (a csg's: its leaf's own space): the shape's (u, v) are worked out
    for image textures only."""
    tex = s.texture[m]
    if tex[TEXTURE_KIND] == NONE:
        return 1.0, 1.0, 1.0
    u, v = 0.0, 0.0
    if g.ints[k, KIND] == CSG_KIND:
        if tex[TEXTURE_KIND] == IMAGE:
            u, v = csg_uv(g, prim, px, py, pz)
        px, py, pz = leaf_point(g, prim % len(g.leaves), px, py, pz)     # as CSG.texture_points
    elif tex[TEXTURE_KIND] == IMAGE:
        u, v = UV_ANY(g.ints[k, KIND], g.objects[k], g.pool, prim, px, py, pz)
    return texture_color(tex, s.texels, px, py, pz, u, v)


@per_ray(inline=True)
def feeler_base(g, s, k, prim, px, py, pz, qx, qy, qz):
    """Where the feelers of a hit leave from (less the offset): the hit p, or with shadow_terminator:
    offset on a smooth triangle or mesh, p plus the `terminator` shift at the object-space point q
    taken to world space (as wavefront.intersect.lifts)."""
    kind = g.ints[k, KIND]
    if not s.terminator or (kind != SMOOTH_KINDS[0] and kind != SMOOTH_KINDS[1]):
        return px, py, pz
    lx, ly, lz = terminator(g.objects[k], g.pool, prim, qx, qy, qz)
    x = g.ints[k, XFORM]
    if x >= 0:
        lx, ly, lz = linear(g.transforms[x], WORLD, lx, ly, lz)
    return px + lx, py + ly, pz + lz


@per_ray(inline=True)
def transmittance(g, s, sx, sy, sz, dx, dy, dz, stack):
    """(r, g, b): how much of a light reaches along the feeler s + t d, 0 < t < 1 (as
    wavefront.intersect.transmittance): 0 behind a full shadow caster, times kt at each surface of
    a `shadow: filter` object, 0 past FEELER_CROSSINGS crossings."""
    if not s.any_filter:
        if scene_hit(g, sx, sy, sz, dx, dy, dz, 0.0, 1.0, ANY_CASTER, stack)[1] >= 0:
            return 0.0, 0.0, 0.0
        return 1.0, 1.0, 1.0
    Tr, Tg, Tb, t0 = 1.0, 1.0, 1.0, 0.0
    for _ in range(FEELER_CROSSINGS):
        t, k, prim = scene_hit(g, sx, sy, sz, dx, dy, dz, t0, 1.0, NEAREST_CASTER, stack)
        if k < 0:
            return Tr, Tg, Tb
        m = material_of(g, k, prim)
        if not s.filters[m]:
            return 0.0, 0.0, 0.0
        Tr, Tg, Tb, t0 = Tr * s.kt[m, 0], Tg * s.kt[m, 1], Tb * s.kt[m, 2], t
    return 0.0, 0.0, 0.0


@per_ray(inline=True)
def feeler(s, f, light, cell):
    """A hit's (frame f) shadow feeler toward sample `cell` of a light: the light point q, the unit
    L toward it and its distance r, N.L, and where the feeler leaves from: the feeler base stepped
    s.offset off the surface along ng, on the lit side."""
    px, py, pz = f[P], f[P + 1], f[P + 2]
    qx, qy, qz = sample_point(light, cell, px, py, pz)
    Lx, Ly, Lz, r = toward(qx, qy, qz, px, py, pz)
    NL = dot(f[N], f[N + 1], f[N + 2], Lx, Ly, Lz)
    sx, sy, sz = f[BASE] + s.offset * f[NG], f[BASE + 1] + s.offset * f[NG + 1], f[BASE + 2] + s.offset * f[NG + 2]
    return qx, qy, qz, Lx, Ly, Lz, r, NL, sx, sy, sz


@per_ray(inline=True)
def through(g, s, f, li, qx, qy, qz, sx, sy, sz, stack):
    """(r, g, b): how much of light li's point q reaches the hit: what a packet found (its feeler
    blocked or not, compiled/tracing.py), else `transmittance` along the feeler from s."""
    if li < PACKED_LIGHTS and (to_int(f[FEELERS]) >> li) & 1:
        lit = 0.0 if (to_int(f[BLOCKED]) >> li) & 1 else 1.0
        return lit, lit, lit
    return transmittance(g, s, sx, sy, sz, qx - sx, qy - sy, qz - sz, stack)


@per_ray(inline=True)
def local(g, s, f, m, counts, stack):
    """The local term for the hit of frame f: emission and ambient, then each light point that sees
    it: N.L > 0 and a shadow feeler from the feeler base stepped off the surface reaching it."""
    Tr, Tg, Tb = f[TEXTURE], f[TEXTURE + 1], f[TEXTURE + 2]
    nx, ny, nz, Vx, Vy, Vz = f[N], f[N + 1], f[N + 2], -f[D], -f[D + 1], -f[D + 2]
    cr, cg, cb = ambient(s, m, s.ambient, Tr, Tg, Tb)
    NV = dot(nx, ny, nz, Vx, Vy, Vz)
    for li in range(len(s.lights)):
        light, samples = s.lights[li], s.samples[li]
        for cell in range(samples):
            qx, qy, qz, Lx, Ly, Lz, r, NL, sx, sy, sz = feeler(s, f, light, cell)
            if not NL > 0:                                              # no contribution (004, case 2)
                continue
            counts[SHADOW] += 1
            T = through(g, s, f, li, qx, qy, qz, sx, sy, sz, stack)
            if not (T[0] > 0 or T[1] > 0 or T[2] > 0):
                continue
            I = (light[COLOR] * T[0], light[COLOR + 1] * T[1], light[COLOR + 2] * T[2])
            w = weight(light, r, Lx, Ly, Lz, samples)
            dr, dg, db = diffuse(s, m, I, w, NL, Tr, Tg, Tb)
            cr, cg, cb = cr + dr, cg + dg, cb + db
            if s.shiny[m]:
                cos = specular_cos(s.blinn, nx, ny, nz, Lx, Ly, Lz, Vx, Vy, Vz, NL, NV)
                sr, sg, sb = specular(s, m, I, w, cos)
                cr, cg, cb = cr + sr, cg + sg, cb + sb
    return cr, cg, cb


@per_ray(inline=True)
def prepare(g, s, ray, hit, f):
    """The hit (t, object, prim) of a ray into its frame f: the point, the facing normals, the unit
    direction, the material, the texture's color and the feeler base; no feeler traced yet. Whether
    the ray hit at all."""
    ox, oy, oz, dx, dy, dz = ray
    t, k, prim = hit
    if k < 0:
        return False
    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
    nx, ny, nz, gx, gy, gz, qx, qy, qz = surface(g, k, prim, t, ox, oy, oz, dx, dy, dz)
    nx, ny, nz, gx, gy, gz, entering = facing(dx, dy, dz, nx, ny, nz, gx, gy, gz)
    m = material_of(g, k, prim)
    Dx, Dy, Dz = unit(dx, dy, dz)
    f[TEXTURE], f[TEXTURE + 1], f[TEXTURE + 2] = texture_at(g, s, m, k, prim, qx, qy, qz)
    f[BASE], f[BASE + 1], f[BASE + 2] = feeler_base(g, s, k, prim, px, py, pz, qx, qy, qz)
    f[P], f[P + 1], f[P + 2], f[N], f[N + 1], f[N + 2] = px, py, pz, nx, ny, nz
    f[NG], f[NG + 1], f[NG + 2], f[D], f[D + 1], f[D + 2] = gx, gy, gz, Dx, Dy, Dz
    f[ENTERING], f[MATERIAL_OF], f[FEELERS], f[BLOCKED] = 1.0 if entering else 0.0, m, 0.0, 0.0
    return True


@per_ray(inline=True)
def finish(g, s, f, counts, stack):
    """The local color of the prepared hit of frame f, and the weights of its secondary rays."""
    m = to_int(f[MATERIAL_OF])
    cr, cg, cb = local(g, s, f, m, counts, stack)
    f[COLOR_SUM], f[COLOR_SUM + 1], f[COLOR_SUM + 2], f[STAGE] = cr, cg, cb, 0
    f[W_REFLECT], f[W_REFLECT + 1], f[W_REFLECT + 2] = s.kr[m, 0], s.kr[m, 1], s.kr[m, 2]
    f[W_REFRACT], f[W_REFRACT + 1], f[W_REFRACT + 2] = 0.0, 0.0, 0.0
    if s.clear[m] or s.fresnel[m]:
        Dx, Dy, Dz, nx, ny, nz = f[D], f[D + 1], f[D + 2], f[N], f[N + 1], f[N + 2]
        n1, n2 = indices(f[MEDIA_IOR:MEDIA_IOR + s.max_depth], int(f[MEDIA_COUNT]), s.medium_ior, s.ior[m],
                         f[ENTERING] != 0)
        eta = n1 / n2
        tx, ty, tz, tir = refract(Dx, Dy, Dz, nx, ny, nz, eta)
        R = fresnel(-dot(Dx, Dy, Dz, nx, ny, nz), eta) if s.fresnel[m] else 0.0      # split needs it only then
        wr, wt = split(s, m, R, tir, s.reflect_tir)
        f[W_REFLECT], f[W_REFLECT + 1], f[W_REFLECT + 2] = wr
        f[W_REFRACT], f[W_REFRACT + 1], f[W_REFRACT + 2] = wt
        f[REFRACTED_DIR], f[REFRACTED_DIR + 1], f[REFRACTED_DIR + 2] = tx, ty, tz
    return cr, cg, cb


@per_ray(inline=True)
def followed(s, f, w, child):
    """Whether the secondary ray of weights f[w:w + 3] is traced: its path weight, the frame's times
    those weights (set in the child frame), is at least adc_bailout in some channel (trace.followed)."""
    r, g, b, traced = path_weight(f[PATH_WEIGHT], f[PATH_WEIGHT + 1], f[PATH_WEIGHT + 2], f[w], f[w + 1], f[w + 2],
                                  s.adc_bailout)
    child[PATH_WEIGHT], child[PATH_WEIGHT + 1], child[PATH_WEIGHT + 2] = r, g, b
    return traced


@per_ray(inline=True)
def next_ray(s, f, child, counts):
    """The frame's next secondary ray (trace.shade): the mirror ray at stage 0 (if its weight is
    not 0), the refracted ray at stage 1 (none past the critical angle: its weight is 0), each only
    if its path weight reaches adc_bailout; (False, _) when none is left. Each starts s.offset off
    the surface, on the side it leaves to; its media go into the child frame (the mirror ray stays
    in the ray's media)."""
    depth = s.max_depth
    ex, ey, ez = s.offset * f[NG], s.offset * f[NG + 1], s.offset * f[NG + 2]
    if f[STAGE] == 0:
        f[STAGE] = 1
        if (f[W_REFLECT] > 0 or f[W_REFLECT + 1] > 0 or f[W_REFLECT + 2] > 0) and followed(s, f, W_REFLECT, child):
            counts[REFLECTED] += 1
            for j in range(MEDIA_COUNT, MEDIA_IOR + depth):
                child[j] = f[j]
            rx, ry, rz = reflect(f[D], f[D + 1], f[D + 2], f[N], f[N + 1], f[N + 2])
            return True, (f[P] + ex, f[P + 1] + ey, f[P + 2] + ez, rx, ry, rz)
    if f[STAGE] == 1:
        f[STAGE] = 2
        if (f[W_REFRACT] > 0 or f[W_REFRACT + 1] > 0 or f[W_REFRACT + 2] > 0) and followed(s, f, W_REFRACT, child):
            counts[REFRACTED] += 1
            m = int(f[MATERIAL_OF])
            child[MEDIA_COUNT] = refracted_media(f[MEDIA_IOR:MEDIA_IOR + depth], int(f[MEDIA_COUNT]), s.ior[m],
                                                 f[ENTERING] != 0, child[MEDIA_IOR:MEDIA_IOR + depth])
            return True, (f[P] - ex, f[P + 1] - ey, f[P + 2] - ez, f[REFRACTED_DIR], f[REFRACTED_DIR + 1],
                          f[REFRACTED_DIR + 2])
    return False, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@per_ray(inline=True)
def radiance(g, s, found, counts, frames, stack):
    """The color seen along one primary ray, whose hit frames[0] holds, prepared (its feelers
    traced by a packet or not: compiled/tracing.py): local + kr radiance(mirror) + kt
    radiance(refracted), depth first with frames[L] the pending hit at depth L + 1 instead of
    recursion."""
    L, ray = 0, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)                       # the secondary ray, once there is one
    frames[0, MEDIA_COUNT] = 0                                        # the camera is in the scene's medium
    frames[0, PATH_WEIGHT:PATH_WEIGHT + 3] = 1.0                      # and the primary's path weight is 1
    while True:
        if L > 0:
            hit = scene_hit(g, ray[0], ray[1], ray[2], ray[3], ray[4], ray[5], 0.0, np.inf, NEAREST, stack)
            found = prepare(g, s, ray, hit, frames[L])
        cr, cg, cb = s.background[0], s.background[1], s.background[2]
        if found:
            cr, cg, cb = finish(g, s, frames[L], counts, stack)
        more = False
        if found and L + 1 < s.max_depth:
            more, ray = next_ray(s, frames[L], frames[L + 1], counts)
        while not more and L > 0:                                     # hand the color to the parent
            L -= 1
            f = frames[L]
            w = W_REFLECT if f[STAGE] == 1 else W_REFRACT
            f[COLOR_SUM], f[COLOR_SUM + 1], f[COLOR_SUM + 2] = (f[COLOR_SUM] + f[w] * cr, f[COLOR_SUM + 1] + f[w + 1] * cg,
                                                                f[COLOR_SUM + 2] + f[w + 2] * cb)
            more, ray = next_ray(s, f, frames[L + 1], counts)
            cr, cg, cb = f[COLOR_SUM], f[COLOR_SUM + 1], f[COLOR_SUM + 2]
        if not more:
            return cr, cg, cb
        L += 1
