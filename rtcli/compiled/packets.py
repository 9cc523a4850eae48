"""Coherent packets: W rays walked through the scene's BVH together (the compiled engine's primary
rays and their feelers toward point lights: compiled/tracing.py), each node's box and each leaf's
triangles or sphere tested for all lanes at once, in vector instructions: loops over the lanes of
the branch-free kernels the one-ray walk calls. A packet is a block of rows of `lanes` (ROWS, W),
a column a ray (compiled/pack.py). Lanes are bits of an int64 mask.

The same answers as the one-ray walk (core/bvh.py `walk`), bit for bit, ties included: each lane
visits the nodes its own walk would, in the same order, against the same best t. A stack entry
holds a node and the lanes that met its box when it was pushed. Where several lanes meet both
children, the packet goes first into the one nearer for its lowest such lane; a lane for which the
other is nearer leaves the packet and is walked alone afterwards. A feeler (ANY_CASTER) never
leaves: whether any caster lies on it does not depend on the order (docs/architecture.md, Packets).
"""

from __future__ import annotations

from rtcli.compiled.pack import (
    BEST,
    CASTS,
    DX,
    DY,
    DZ,
    IX,
    IY,
    IZ,
    KIND,
    KINDS,
    LISTED,
    MESH,
    OBJECT_RAYS,
    OX,
    OY,
    OZ,
    PRIM,
    T_MAX,
    T_MIN,
    TREE,
    WON,
    WORLD_RAYS,
    XFORM,
    W,
)
from rtcli.compiled.query import WALK_OBJECTS, object_leaf, object_leaf_one, scene_hit
from rtcli.core.bvh import ANY_CASTER, CHILD, COUNT, NEAREST, START, reciprocal, slab
from rtcli.core.transform import ray_to_object
from rtcli.kernels.variants import INF, compiled, per_ray, to_int
from rtcli.shapes import SHAPES
from rtcli.shapes.sphere import hit as sphere_hit
from rtcli.shapes.triangle import triangle_t

ALL = (1 << W) - 1
MESH_KIND, SPHERE_KIND = KINDS[SHAPES["mesh"]], KINDS[SHAPES["sphere"]]
ROOT_AT, FIRST_AT = SHAPES["mesh"].ROOT_COLUMN, SHAPES["mesh"].FIRST_COLUMN
RAYS = OUT = 0                                        # bound per walk: its block of rays and of answers


@per_ray(inline=True)
def lane(mask, l):
    """Whether lane l is in the mask."""
    return (mask >> l) & 1 != 0


@per_ray(inline=True)
def meets(g, node, pk, lanes, rays, out):
    """The lanes (of `lanes`) whose ray (block `rays`) meets node's box within [t_min, best] (best:
    in block `out`): the one-ray walk's `entry`, for W rays at once."""
    lox, loy, loz = g.nodes[node, 0], g.nodes[node, 1], g.nodes[node, 2]
    hix, hiy, hiz = g.nodes[node, 3], g.nodes[node, 4], g.nodes[node, 5]
    met = 0
    for l in range(W):
        t_in, t_out = slab(lox, loy, loz, hix, hiy, hiz, pk[rays + OX, l], pk[rays + OY, l], pk[rays + OZ, l],
                           pk[rays + IX, l], pk[rays + IY, l], pk[rays + IZ, l], pk[T_MIN, l], pk[out + BEST, l])
        met |= (1 if t_in <= t_out else 0) << l
    return met & lanes


@per_ray(inline=True)
def children(g, child, pk, lanes, rays, out):
    """(the lanes meeting child's box, those meeting child + 1's, those for which child + 1's entry
    is the nearer one): the one-ray walk's test of a node's two children, for W rays at once."""
    a, b, met0, met1, swap = child, child + 1, 0, 0, 0
    for l in range(W):
        ox, oy, oz = pk[rays + OX, l], pk[rays + OY, l], pk[rays + OZ, l]
        ix, iy, iz = pk[rays + IX, l], pk[rays + IY, l], pk[rays + IZ, l]
        near, far = pk[T_MIN, l], pk[out + BEST, l]
        in0, out0 = slab(g.nodes[a, 0], g.nodes[a, 1], g.nodes[a, 2], g.nodes[a, 3], g.nodes[a, 4], g.nodes[a, 5],
                         ox, oy, oz, ix, iy, iz, near, far)
        in1, out1 = slab(g.nodes[b, 0], g.nodes[b, 1], g.nodes[b, 2], g.nodes[b, 3], g.nodes[b, 4], g.nodes[b, 5],
                         ox, oy, oz, ix, iy, iz, near, far)
        e0 = in0 if in0 <= out0 else INF
        e1 = in1 if in1 <= out1 else INF
        met0 |= (1 if e0 < INF else 0) << l
        met1 |= (1 if e1 < INF else 0) << l
        swap |= (1 if e1 < e0 else 0) << l
    return met0 & lanes, met1 & lanes, swap & lanes


@per_ray
def packet_walk(g, root, pk, alive, shadow, stack, bottom):
    """`walk` (core/bvh.py) of the tree at `root` for the packet's alive lanes, each lane's answer
    into its OUT rows (set by the caller: best t_max, won -1); LEAF_PACKET tests a leaf entry.
    Returns the lanes that left the packet (their answers are not set)."""
    left = 0
    stack[bottom], stack[bottom + 1], top, tested = root, alive, bottom + 2, False
    while top > bottom:
        top -= 2
        node, lanes = stack[top], stack[top + 1] & alive
        if lanes != 0 and not tested:
            lanes = meets(g, node, pk, lanes, RAYS, OUT)
        tested = False
        if lanes == 0:
            continue
        child = g.links[node, CHILD]
        if child >= 0:
            met0, met1, swap = children(g, child, pk, lanes, RAYS, OUT)
            both = met0 & met1
            order = 1 if (swap & both & -both) != 0 else 0                # the lowest lane's order
            gone = both & (swap ^ (ALL if order else 0))                  # lanes that would go the other way,
            gone = 0 if shadow == ANY_CASTER else gone                    # which matters only for the nearest
            left, alive, met0, met1 = left | gone, alive & ~gone, met0 & ~gone, met1 & ~gone
            first, second, met_first, met_second = child, child + 1, met0, met1
            if order:
                first, second, met_first, met_second = child + 1, child, met1, met0
            if met_second != 0:
                stack[top], stack[top + 1], top = second, met_second, top + 2
            if met_first != 0:
                stack[top], stack[top + 1], top, tested = first, met_first, top + 2, True
            continue
        start = g.links[node, START]
        for j in range(start, start + g.links[node, COUNT]):
            lanes &= alive
            if lanes == 0:
                break
            done, gone = LEAF_PACKET(g, g.perm[j], pk, lanes, shadow, stack, top)  # noqa: F821
            left, alive = left | gone, alive & ~(done | gone)
    for l in range(W):
        if pk[OUT + WON, l] < 0:
            pk[OUT + BEST, l] = INF
    return left


@per_ray(inline=True)
def triangle_packet(g, j, pk, lanes, shadow, stack, bottom):
    """A mesh tree's leaf entry, triangle j of g.pool, for the packet's lanes: each lane's best
    lowered where it hits nearer (`triangle_leaf`, then `walk`'s step); (the lanes done: with
    ANY_CASTER, those that hit; no lane leaves)."""
    hit, r = 0, OBJECT_RAYS
    for l in range(W):
        t = triangle_t(g.pool, j, pk[r + OX, l], pk[r + OY, l], pk[r + OZ, l], pk[r + DX, l], pk[r + DY, l],
                       pk[r + DZ, l])
        nearer = lane(lanes, l) & (pk[T_MIN, l] < t) & (t < pk[MESH + BEST, l])
        pk[MESH + BEST, l] = t if nearer else pk[MESH + BEST, l]
        pk[MESH + WON, l] = j if nearer else pk[MESH + WON, l]
        hit |= (1 if nearer else 0) << l
    return (hit if shadow == ANY_CASTER else 0), 0


WALK_MESH = compiled(packet_walk, LEAF_PACKET=triangle_packet, RAYS=OBJECT_RAYS, OUT=MESH)


@per_ray(inline=True)
def mesh_packet(g, k, pk, lanes, shadow, stack, bottom):
    """A mesh object's packet walk: the lanes' rays taken into its space (OBJECT_RAYS), its own tree
    walked with each lane's best so far, and each lane's answer taken where it is nearer. (The
    lanes done, those that left.)"""
    x, r = g.ints[k, XFORM], OBJECT_RAYS
    for l in range(W):
        ox, oy, oz, dx, dy, dz = pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l]
        if x >= 0:
            ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
        pk[r + OX, l], pk[r + OY, l], pk[r + OZ, l] = ox, oy, oz
        pk[r + DX, l], pk[r + DY, l], pk[r + DZ, l] = dx, dy, dz
        pk[r + IX, l], pk[r + IY, l], pk[r + IZ, l] = reciprocal(dx), reciprocal(dy), reciprocal(dz)
        pk[MESH + BEST, l], pk[MESH + WON, l] = pk[TREE + BEST, l], -1.0
    gone = WALK_MESH(g, to_int(g.objects[k, ROOT_AT]), pk, lanes, shadow, stack, bottom)
    first, hit = g.objects[k, FIRST_AT], 0
    for l in range(W):
        nearer = lane(lanes & ~gone, l) and pk[MESH + WON, l] >= 0 and pk[MESH + BEST, l] < pk[TREE + BEST, l]
        if nearer:
            pk[TREE + BEST, l], pk[TREE + WON, l], pk[TREE + PRIM, l] = pk[MESH + BEST, l], k, \
                pk[MESH + WON, l] - first
            hit |= 1 << l
    return (hit if shadow == ANY_CASTER else 0), gone


@per_ray(inline=True)
def sphere_packet(g, k, pk, lanes, shadow):
    """A sphere object for the packet's lanes, all at once: each lane's ray taken into its space,
    the sphere's hit (shapes/sphere.py), and each lane's best lowered where it hits nearer."""
    x, hit = g.ints[k, XFORM], 0
    for l in range(W):
        ox, oy, oz, dx, dy, dz = pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l]
        if x >= 0:
            ox, oy, oz, dx, dy, dz = ray_to_object(g.transforms[x], 0, ox, oy, oz, dx, dy, dz)
        t, _ = sphere_hit(g.objects[k], g.pool, ox, oy, oz, dx, dy, dz, pk[T_MIN, l], pk[TREE + BEST, l])
        nearer = lane(lanes, l) & (t < pk[TREE + BEST, l])
        pk[TREE + BEST, l] = t if nearer else pk[TREE + BEST, l]
        pk[TREE + WON, l] = k if nearer else pk[TREE + WON, l]
        pk[TREE + PRIM, l] = 0.0 if nearer else pk[TREE + PRIM, l]
        hit |= (1 if nearer else 0) << l
    return (hit if shadow == ANY_CASTER else 0), 0


@per_ray(inline=True)
def alone(g, k, pk, lanes, shadow, stack, bottom):
    """Object k for the packet's lanes one by one, by ONE (`object_leaf`: a call of its own for the
    tree's leaves, inline for the listed objects, where a call per lane would cost more than a
    plane's test). (The lanes done, none that left.)"""
    hit = 0
    for l in range(W):
        if lane(lanes, l):
            t, p = ONE(g, k, pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l],  # noqa: F821
                       pk[T_MIN, l], pk[TREE + BEST, l], shadow, stack, bottom)
            if t < pk[TREE + BEST, l]:
                pk[TREE + BEST, l], pk[TREE + WON, l], pk[TREE + PRIM, l] = t, k, p
                hit |= 1 << l
    return (hit if shadow == ANY_CASTER else 0), 0


@per_ray(inline=True)
def object_packet(g, k, pk, lanes, shadow, stack, bottom):
    """Object k (a leaf entry of the scene's tree, or a listed object) for the packet's lanes: a
    mesh walked as a packet, a sphere tested for all lanes at once, any other shape by ALONE. (The
    lanes done, those that left.)"""
    if shadow != NEAREST and g.ints[k, CASTS] == 0:
        return 0, 0
    if g.ints[k, KIND] == MESH_KIND:
        return mesh_packet(g, k, pk, lanes, shadow, stack, bottom)
    if g.ints[k, KIND] == SPHERE_KIND:
        return sphere_packet(g, k, pk, lanes, shadow)
    return ALONE(g, k, pk, lanes, shadow, stack, bottom)  # noqa: F821


TREE_LEAF = compiled(object_packet, ALONE=compiled(alone, ONE=object_leaf_one))
LISTED_OBJECT = compiled(object_packet, ALONE=compiled(alone, ONE=object_leaf))
WALK_SCENE = compiled(packet_walk, LEAF_PACKET=TREE_LEAF, RAYS=WORLD_RAYS, OUT=TREE)


@per_ray
def scene_hit_packet(g, pk, wanted, shadow, stack):
    """`scene_hit` (compiled/query.py) for the packet's lanes in `wanted` (their rays and
    intervals set): each lane's (t, object, prim) into its LISTED rows. The listed objects as the
    scene tree's leaves are (a mesh among them, say a scene's only object, walked as a packet),
    then the scene's tree as a packet, then each lane that left alone; returns those lanes."""
    alive = 0
    for l in range(W):
        if lane(wanted, l):
            pk[IX, l], pk[IY, l], pk[IZ, l] = reciprocal(pk[DX, l]), reciprocal(pk[DY, l]), reciprocal(pk[DZ, l])
            pk[TREE + BEST, l], pk[TREE + WON, l], pk[TREE + PRIM, l] = pk[T_MAX, l], -1.0, 0.0
            alive |= 1 << l
    gone_listed = 0
    for j in range(len(g.listed)):
        if alive == 0:
            break
        done, gone = LISTED_OBJECT(g, g.listed[j], pk, alive, shadow, stack, 0)
        gone_listed, alive = gone_listed | gone, alive & ~(done | gone)
    left = 0
    for l in range(W):                                    # the listed objects' answers; the tree's next
        pk[LISTED + BEST, l], pk[LISTED + WON, l], pk[LISTED + PRIM, l] = pk[TREE + BEST, l], pk[TREE + WON, l], \
            pk[TREE + PRIM, l]
        pk[TREE + WON, l] = -1.0
    if alive != 0 and not (g.links[0, CHILD] < 0 and g.links[0, COUNT] == 0):    # a tree (not a scene of few objects)
        left = WALK_SCENE(g, 0, pk, alive, shadow, stack, 0)
    for l in range(W):
        if lane(gone_listed, l):
            t, k, p = scene_hit(g, pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l], pk[T_MIN, l],
                                pk[T_MAX, l], shadow, stack)
        elif lane(left, l):
            t, k, p = WALK_OBJECTS(g, 0, pk[OX, l], pk[OY, l], pk[OZ, l], pk[DX, l], pk[DY, l], pk[DZ, l],
                                   pk[T_MIN, l], pk[LISTED + BEST, l], shadow, stack, 0)
        elif lane(alive, l) and pk[TREE + WON, l] >= 0:
            t, k, p = pk[TREE + BEST, l], to_int(pk[TREE + WON, l]), to_int(pk[TREE + PRIM, l])
        else:
            continue
        if k >= 0 or lane(gone_listed, l):
            pk[LISTED + BEST, l], pk[LISTED + WON, l], pk[LISTED + PRIM, l] = t, k, p
    return left | gone_listed


@per_ray(entry=True)
def packet_rays(g, o, d, t_min, t_max, shadow, t, hit, prim, stack, pk, left):
    """scene_hit_packet over the rays o, d (3, n), W at a time: into t, hit (the object, -1 on a
    miss) and prim (n,), and into left (n,) 1 for a ray that left its packet; the packets'
    counterpart of query.scene_rays, for tests."""
    for i0 in range(0, o.shape[1], W):
        n = min(W, o.shape[1] - i0)
        for l in range(n):
            for r in range(3):
                pk[OX + r, l], pk[DX + r, l] = o[r, i0 + l], d[r, i0 + l]
            pk[T_MIN, l], pk[T_MAX, l] = t_min[i0 + l], t_max[i0 + l]
        gone = scene_hit_packet(g, pk, (1 << n) - 1, shadow, stack)
        for l in range(n):
            t[i0 + l], hit[i0 + l], left[i0 + l] = pk[LISTED + BEST, l], to_int(pk[LISTED + WON, l]), (gone >> l) & 1
            prim[i0 + l] = to_int(pk[LISTED + PRIM, l])
