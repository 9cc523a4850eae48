"""Glass: the medium a ray travels in, Fresnel's equations, and the weights of the two rays a
transparent surface sends on (notes 000 11.7.3: "keep track of the speed of light in the
current medium"; docs/scene-format.md, Shading).

**Media.** Each ray carries the media it is inside, as a stack of their indices of refraction:
`count` of them in `ior[0:count]`, the innermost last. A ray crossing into a transparent solid
pushes the solid's ior; one crossing out of it removes the topmost entry equal to that ior,
wherever it is. Nested solids (an air bubble in glass, a glass in water) thus get the right
n1 and n2 at every surface, and a solid may be made of several surfaces, even of several
materials with the same ior (two polygons bounding a slab, the children of a csg). Outside every
solid the medium is the scene's `medium_ior` (the camera's). At a surface of ior m, n1 is the
medium the ray is in (m itself when it leaves) and n2 the medium beyond: m when entering, else
the top of the stack once m's entry is gone. Solids that overlap without nesting are followed
by their iors alone: where two with the same ior straddle a third, leaving one may remove the
other's entry. Stacks are columns (D, n) in the numpy engine and rows (D,) of the compiled
engine's frames: the loops run over the D slots, the same for every ray.

**Fresnel.** The exact reflectance of a dielectric interface for unpolarised light,
R = (Rs + Rp) / 2 (not Schlick's approximation), and 1 at total internal reflection.

**Weights.** The mirror ray carries kr and the refracted ray kt; with `fresnel: true` they carry
kr R and kt (1 - R), so their sum never exceeds max(kr, kt). Past the critical angle the
refracted ray does not exist: `total_internal_reflection: drop` (the notes' rule, the default)
loses its weight; `reflect` adds kt to the mirror ray's, as POV-Ray does. With Fresnel, R = 1
already sends the light to the mirror ray, so the setting does not apply.
"""

from __future__ import annotations

from rtcli.kernels.variants import kernel, not_, select, sqrt

FEELER_CROSSINGS = 64       # surfaces a filtered shadow feeler may cross; past them the light is stopped


@kernel
def fresnel(cos_i, eta):
    """Reflectance R for unit cos_i >= 0 (the angle to the normal on the incoming side) and
    eta = n1 / n2: Rs = ((eta cos_i - cos_t) / (eta cos_i + cos_t))^2,
    Rp = ((cos_i - eta cos_t) / (cos_i + eta cos_t))^2, R = (Rs + Rp) / 2; 1 past the critical angle."""
    k = 1 - eta * eta * (1 - cos_i * cos_i)              # cos^2 theta_t
    cos_t = sqrt(select(k > 0, k, 0.0))
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return select(k < 0, 1.0, (rs * rs + rp * rp) / 2)


@kernel(inline=True)
def split(mats, m, R, tir, reflect_tir):
    """(wr, wt), each (r, g, b): the weights of the mirror ray and of the refracted ray at a hit on
    material m, given the reflectance R and whether the refracted ray is past the critical angle."""
    use = mats.fresnel[m] != 0
    fr, ft = select(use, R, 1.0), select(use, 1.0 - R, 1.0)
    gone = tir & not_(use) & reflect_tir                  # its weight goes to the mirror ray
    kept = not_(tir)
    wr = (mats.kr[m, 0] * fr + select(gone, mats.kt[m, 0], 0.0),
          mats.kr[m, 1] * fr + select(gone, mats.kt[m, 1], 0.0),
          mats.kr[m, 2] * fr + select(gone, mats.kt[m, 2], 0.0))
    wt = (select(kept, mats.kt[m, 0] * ft, 0.0), select(kept, mats.kt[m, 1] * ft, 0.0),
          select(kept, mats.kt[m, 2] * ft, 0.0))
    return wr, wt


@kernel
def entry(stack, count, below, outside):
    """The entry `below` places under the top of a stack (below = 0: the top), or `outside`
    where there is none."""
    value = outside
    for j in range(len(stack)):
        value = select(j == count - 1 - below, stack[j], value)
    return value


@kernel
def indices(ior, count, outside, ior_m, entering):
    """(n1, n2) at a surface of a solid of index ior_m that the ray enters or leaves."""
    current = entry(ior, count, 0, outside)
    beyond = select(current == ior_m, entry(ior, count, 1, outside), current)
    return select(entering, current, ior_m), select(entering, ior_m, beyond)


@kernel
def refracted_media(ior, count, ior_m, entering, out_ior):
    """The stack of the refracted ray, into out_ior (the shape of ior): ior_m pushed when entering,
    the topmost entry equal to it removed when leaving. Returns its count."""
    size = len(ior)
    place = -1 + 0 * count                                # the topmost entry equal to ior_m, -1 if none
    for j in range(size):
        place = select((j < count) & (ior[j] == ior_m), j, place)
    leaves = not_(entering) & (place >= 0)
    for j in range(size):
        above = ior[j + 1] if j + 1 < size else ior[j]
        out_ior[j] = select(entering & (j == count), ior_m, select(leaves & (j >= place), above, ior[j]))
    return select(entering, count + 1, select(leaves, count - 1, count))
