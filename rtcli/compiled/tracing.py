"""The compiled engine's entry: the camera rays of a tile, W at a time, their first hits and their
shadow feelers toward each point light traced as packets (compiled/packets.py), then each ray on
its own through the integrator (compiled/integrator.py).

For each packet of W pixels:
1. the primary rays' hits, as one packet;
2. each hit prepared in a frame of its own (integrator.prepare: point, normals, material, texture,
   feeler base);
3. for each light of one sample (a point or spot light), the feelers of the hits it faces
   (N.L > 0), from the same points in the same directions as the integrator's `feeler` makes them,
   as one packet looking for any shadow caster; each frame notes which lights' feelers were
   traced and which were blocked. A scene with `shadow: filter` objects has its feelers traced
   one at a time (they need the nearest caster, several times);
4. each ray's color, `radiance` reading the frame's feelers where it would trace them.

So every ray, feeler and color is the one the one-ray integrator makes, in the same arithmetic:
the pixels are the same, bit for bit.
"""

from __future__ import annotations

import numpy as np

from rtcli.compiled.integrator import feeler, prepare, radiance
from rtcli.compiled.pack import (
    BEST,
    BLOCKED,
    DX,
    DY,
    DZ,
    FEELERS,
    LISTED,
    MEDIA_COUNT,
    OX,
    OY,
    OZ,
    PACKED_LIGHTS,
    PRIM,
    T_MAX,
    T_MIN,
    WON,
    W,
)
from rtcli.compiled.packets import scene_hit_packet
from rtcli.core.bvh import ANY_CASTER, NEAREST
from rtcli.core.camera import primary_ray
from rtcli.kernels.variants import per_ray, to_int


@per_ray(inline=True)
def set_lane(pk, l, ox, oy, oz, dx, dy, dz, t_min, t_max):
    """Lane l of a packet: the ray o + t d, t in (t_min, t_max)."""
    pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l] = ox, oy, oz, dx, dy, dz
    pk[T_MIN, l], pk[T_MAX, l] = t_min, t_max


@per_ray(inline=True)
def feelers(g, s, hits, frames, first, pk, stack):
    """Step 3 above, for the packet's hits (a mask of lanes; lane l's frame: frames[first + l])."""
    if s.any_filter:
        return
    for li in range(min(len(s.lights), PACKED_LIGHTS)):
        if s.samples[li] != 1:
            continue
        wanted = 0
        for l in range(W):
            if (hits >> l) & 1:
                qx, qy, qz, _, _, _, _, NL, sx, sy, sz = feeler(s, frames[first + l], s.lights[li], 0)
                if NL > 0:
                    set_lane(pk, l, sx, sy, sz, qx - sx, qy - sy, qz - sz, 0.0, 1.0)
                    wanted |= 1 << l
        if wanted == 0:
            continue
        scene_hit_packet(g, pk, wanted, ANY_CASTER, stack)
        for l in range(W):
            if (wanted >> l) & 1:
                f = frames[first + l]
                f[FEELERS] = to_int(f[FEELERS]) | (1 << li)
                if pk[LISTED + WON, l] >= 0:
                    f[BLOCKED] = to_int(f[BLOCKED]) | (1 << li)


@per_ray(entry=True)
def trace_camera(g, s, cam, x, y, nc, nr, counts, stack, out, frames, lanes):
    """The colors of the primary rays through the pixel coordinates (x, y) (n,) of a camera (its
    row: rtcli/core/camera.py) into out (n, 3), W at a time (above). The caller gives the scratch:
    stack (the traversal's), frames (pack.frames) and lanes (pack.lanes), so that this entry
    allocates nothing and runs as machine code without numba (rtcli/kernels/machinecode)."""
    first = len(frames) - W                           # the lanes' frames: frames[first + l]
    for i0 in range(0, len(x), W):
        n = min(W, len(x) - i0)
        for l in range(n):
            ox, oy, oz, dx, dy, dz = primary_ray(cam, x[i0 + l], y[i0 + l], nc, nr)
            set_lane(lanes, l, ox, oy, oz, dx, dy, dz, 0.0, np.inf)
        scene_hit_packet(g, lanes, (1 << n) - 1, NEAREST, stack)
        hits = 0
        for l in range(n):
            ray = (lanes[OX, l], lanes[OY, l], lanes[OZ, l], lanes[DX, l], lanes[DY, l], lanes[DZ, l])
            hit = (lanes[LISTED + BEST, l], to_int(lanes[LISTED + WON, l]), to_int(lanes[LISTED + PRIM, l]))
            if prepare(g, s, ray, hit, frames[first + l]):
                hits |= 1 << l
        feelers(g, s, hits, frames, first, lanes, stack)
        for l in range(n):
            for c in range(MEDIA_COUNT):                              # the hit, into the primary's frame
                frames[0, c] = frames[first + l, c]
            out[i0 + l] = radiance(g, s, (hits >> l) & 1 != 0, counts, frames, stack)
