"""The local term of the shading equation (docs/scene-format.md, Shading; notes 000 11.7, 002, 004):

    emission + ka Ia T + sum over lights not in shadow with N.L > 0:
                         att(r) I (kd T (N.L) + ks spec)

spec = max(0, R.V)^n with R = 2(N.L)N - L (phong), or max(0, N.H)^n with
H = norm(L + V) (blinn). Products of colors are per channel. Each piece is a kernel
that both engines call; which lights a point sees (the shadow feelers) is the
engines' own business. `mats` is a MaterialTable (or the compiled engine's copy of
its arrays), `m` the material of each hit.
"""

from __future__ import annotations

from rtcli.core.elementary import power
from rtcli.core.vec import dot
from rtcli.kernels.variants import kernel, maximum, select, sqrt


@kernel(inline=True)
def ambient(mats, m, Ia, Tr, Tg, Tb):
    """emission + ka Ia T, the light every point gets."""
    return (mats.emission[m, 0] + mats.ka[m, 0] * Ia[0] * Tr,
            mats.emission[m, 1] + mats.ka[m, 1] * Ia[1] * Tg,
            mats.emission[m, 2] + mats.ka[m, 2] * Ia[2] * Tb)


@kernel(inline=True)
def diffuse(mats, m, I, w, NL, Tr, Tg, Tb):
    """w (N.L) I kd T: the diffuse term of one light point of weight w = att(r) x spot / samples."""
    wNL = w * NL
    return (wNL * I[0] * (mats.kd[m, 0] * Tr), wNL * I[1] * (mats.kd[m, 1] * Tg),
            wNL * I[2] * (mats.kd[m, 2] * Tb))


@kernel
def specular_cos(blinn, Nx, Ny, Nz, Lx, Ly, Lz, Vx, Vy, Vz, NL, NV):
    """R.V with R = 2(N.L)N - L, so R.V = 2(N.L)(N.V) - L.V (phong); or N.H, H = norm(L + V) (blinn)."""
    if blinn:
        Hx, Hy, Hz = Lx + Vx, Ly + Vy, Lz + Vz
        return dot(Nx, Ny, Nz, Hx, Hy, Hz) / sqrt(Hx * Hx + Hy * Hy + Hz * Hz)
    return 2 * NL * NV - dot(Lx, Ly, Lz, Vx, Vy, Vz)


@kernel(inline=True)
def specular(mats, m, I, w, cos):
    """w max(0, cos)^n I ks: the specular term of one light point."""
    ws = w * power(maximum(cos, 0.0), mats.shininess[m])
    return ws * I[0] * mats.ks[m, 0], ws * I[1] * mats.ks[m, 1], ws * I[2] * mats.ks[m, 2]


@kernel
def facing(dx, dy, dz, nx, ny, nz, gx, gy, gz):
    """The unit shading normal n and geometric normal g turned to face a ray of direction d, and
    whether the ray enters (arrives against the outward g). A shading normal that still points
    away from the ray (a smooth normal past the silhouette) gives way to the geometric one."""
    entering = dot(dx, dy, dz, gx, gy, gz) < 0
    s = select(entering, 1.0, -1.0)
    nx, ny, nz, gx, gy, gz = nx * s, ny * s, nz * s, gx * s, gy * s, gz * s
    away = dot(nx, ny, nz, dx, dy, dz) > 0
    return select(away, gx, nx), select(away, gy, ny), select(away, gz, nz), gx, gy, gz, entering


@kernel(inline=True)
def path_weight(pr, pg, pb, wr, wg, wb, bailout):
    """A secondary ray's path weight, the product of the weights of the surfaces before it (its
    parent's path weight times its own weight, per channel), and whether it is traced: at least
    adc_bailout in some channel (docs/scene-format.md, Adaptive depth control)."""
    r, g, b = pr * wr, pg * wg, pb * wb
    return r, g, b, (r >= bailout) | (g >= bailout) | (b >= bailout)
