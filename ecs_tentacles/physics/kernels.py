"""The numba kernels of the physics' per-frame queries: the contact proxies' `sense`
(gather every body and every reach sphere in one pass) and `reach` (the spheres alone:
a frame copies only the bodies it needs, `gather`; `reach_parallel` on all cores for a
large crowd), the near pairs' tests (reading bodies where they are; every pair of a
small crowd; how far the spheres moved since the pair cache's tree was asked,
`largest_move`) and the proxies' candidate bodies (the heightfield's heights are
`terrain.heightfield_kernels`').

Optional, as the other kernels are: their users import this module only when numba is
installed and fall back to numpy otherwise; both compute the same numbers bit for bit
(the same operations in the same order; tests/physics/test_contacts.py compares them).
At 10,000 creatures (810,000 bodies) the numpy path took about 55 ms a frame: two
gathers, a subtraction, a norm and a `maximum.reduceat`, each a pass over every body.
"""

from __future__ import annotations

import math
import os

import numpy as np

# OpenMP's worker threads (numba's "omp" layer, `reach_parallel`) spin after each parallel
# kernel by default, taking the cores from the stepping threads; passive ones sleep. Read
# when numba first starts its pool: the fur rig's kernels set the same
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from numba import njit, prange


@njit(cache=True, nogil=True)
def sense(
    store_pos: np.ndarray,
    store_quat: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    rbound: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """Bodies `rows` of the Transform store into `out_pos` / `out_quat` (creature by
    creature: creature c owns `count[c]` bodies from `start[c]`, its mantle first); each
    creature's reach sphere (mantle centre, farthest body surface) into `out_centre` /
    `out_radius`."""
    for i in range(len(rows)):
        row = rows[i]
        for j in range(3):
            out_pos[i, j] = store_pos[row, j]
        for j in range(4):
            out_quat[i, j] = store_quat[row, j]
    for c in range(len(start)):
        _sphere(store_pos, rows, start[c], count[c], rbound, c, out_centre, out_radius)


@njit(cache=True, nogil=True)
def gather(
    store_pos: np.ndarray,
    store_quat: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    creatures: np.ndarray,
    gathered: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
) -> None:
    """The bodies of `creatures` not `gathered` yet into `out_pos` / `out_quat` (`sense`'s
    copies, for those creatures only), marking them gathered."""
    for c in creatures:
        if gathered[c]:
            continue
        gathered[c] = True
        for i in range(start[c], start[c] + count[c]):
            row = rows[i]
            for j in range(3):
                out_pos[i, j] = store_pos[row, j]
            for j in range(4):
                out_quat[i, j] = store_quat[row, j]


@njit(cache=True, nogil=True)
def reach(
    store_pos: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    rbound: np.ndarray,
    creatures: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """`sense`'s reach spheres alone, of `creatures`: no body is copied (a frame needs the
    bodies of the creatures near another only, `ContactProxies.gather`; a replayed
    creature's sphere was found as its poses were written)."""
    for c in creatures:
        _sphere(store_pos, rows, start[c], count[c], rbound, c, out_centre, out_radius)


@njit(cache=True, nogil=True, parallel=True)
def reach_parallel(
    store_pos: np.ndarray,
    rows: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    rbound: np.ndarray,
    creatures: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """`reach` on all cores, creature by creature (each sphere's numbers are `reach`'s)."""
    for i in prange(len(creatures)):
        c = creatures[i]
        _sphere(store_pos, rows, start[c], count[c], rbound, c, out_centre, out_radius)


@njit(cache=True, nogil=True, inline="always")
def _sphere(
    pos: np.ndarray,
    rows: np.ndarray,
    first: int,
    count: int,
    rbound: np.ndarray,
    c: int,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """Creature c's reach sphere from its `count` bodies from `first` (body i at
    `pos[rows[i]]`, its mantle first): centre at the mantle, radius to the farthest
    body's surface."""
    mantle = rows[first]
    cx, cy, cz = pos[mantle, 0], pos[mantle, 1], pos[mantle, 2]
    out_centre[c, 0], out_centre[c, 1], out_centre[c, 2] = cx, cy, cz
    radius = -np.inf
    for i in range(first, first + count):
        row = rows[i]
        dx, dy, dz = pos[row, 0] - cx, pos[row, 1] - cy, pos[row, 2] - cz
        reach = math.sqrt(dx * dx + dy * dy + dz * dz) + rbound[i]
        if reach > radius:
            radius = reach
    out_radius[c] = radius


@njit(cache=True, nogil=True)
def moved_bodies(
    used: np.ndarray,
    members: np.ndarray,
    start: np.ndarray,
    every: np.ndarray,
    rbound: np.ndarray,
    xpos: np.ndarray,
    xquat: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """`ContactProxies.refresh` for one batch: the bodies of its rows whose creature is
    `used` (`members[r]`, roster order) from their last step (`xpos[r]`, `xquat[r]`) into
    `out_pos` / `out_quat` (creature c's bodies from `start[c]`), and those creatures'
    reach spheres (`reach`'s, body i at `out_pos[every[i]]`) into `out_centre` /
    `out_radius`."""
    bodies = xpos.shape[1]
    for r in range(len(members)):
        c = members[r]
        if not used[c]:
            continue
        first = start[c]
        for j in range(bodies):
            for k in range(3):
                out_pos[first + j, k] = xpos[r, j, k]
            for k in range(4):
                out_quat[first + j, k] = xquat[r, j, k]
        _sphere(out_pos, every, first, bodies, rbound, c, out_centre, out_radius)


@njit(cache=True, nogil=True)
def pair_gaps(
    pos: np.ndarray,
    where: np.ndarray,
    centre: np.ndarray,
    radius: np.ndarray,
    rbound: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    margin: float,
    out_gaps: np.ndarray,
) -> None:
    """For each pair (a[p], b[p]), the gap between their nearest bodies into `out_gaps[p]`
    (left as it is where no body of one comes within `margin` of the other's reach
    sphere): `ContactProxies.pair_gaps`'s numbers, pair by pair, without the arrays of
    every candidate body (at 10,000 creatures about 7 ms a frame in numpy). Body i is at
    `pos[where[i]]` (the Transform store and its rows: no body is copied first)."""
    most = 0
    for c in range(len(count)):
        most = max(most, count[c])
    near_a = np.empty(most, dtype=np.int64)
    near_b = np.empty(most, dtype=np.int64)
    for p in range(len(a)):
        na = _inside(pos, where, centre, radius, rbound, start, count, a[p], b[p], margin, near_a)
        if na == 0:
            continue
        nb = _inside(pos, where, centre, radius, rbound, start, count, b[p], a[p], margin, near_b)
        best = out_gaps[p]
        for i in range(na):
            u = near_a[i]
            pu = where[u]
            for j in range(nb):
                v = near_b[j]
                pv = where[v]
                dx, dy = pos[pu, 0] - pos[pv, 0], pos[pu, 1] - pos[pv, 1]
                dz = pos[pu, 2] - pos[pv, 2]
                gap = math.sqrt(dx * dx + dy * dy + dz * dz) - rbound[u] - rbound[v]
                if gap < best:
                    best = gap
        out_gaps[p] = best


@njit(cache=True, nogil=True)
def _inside(
    pos: np.ndarray,
    where: np.ndarray,
    centre: np.ndarray,
    radius: np.ndarray,
    rbound: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    x: int,
    y: int,
    margin: float,
    out: np.ndarray,
) -> int:
    """Bodies of creature x within `margin` of y's reach sphere into `out`; how many."""
    n = 0
    cx, cy, cz = centre[y, 0], centre[y, 1], centre[y, 2]
    limit = radius[y] + margin
    for body in range(start[x], start[x] + count[x]):
        at = where[body]
        dx, dy, dz = pos[at, 0] - cx, pos[at, 1] - cy, pos[at, 2] - cz
        if math.sqrt(dx * dx + dy * dy + dz * dz) - rbound[body] < limit:
            out[n] = body
            n += 1
    return n


@njit(cache=True, nogil=True)
def proxy_candidates(
    pos: np.ndarray,
    centre: np.ndarray,
    radius: np.ndarray,
    rbound: np.ndarray,
    start: np.ndarray,
    count: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    margin: float,
    crowded_over: int,
    creatures: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """`ContactProxies._assign`'s candidates, its numbers without its temporaries: for
    each pair p, the bodies of b[p] within `margin` of a[p]'s reach sphere as (who = a[p],
    body, gap); where a creature has more than `crowded_over` candidates, each of its
    candidates' gap is to the creature's nearest own body instead (`_body_gaps`)."""
    total = 0
    for p in range(len(b)):
        total += count[b[p]]
    who = np.empty(total, dtype=np.int64)
    body = np.empty(total, dtype=np.int64)
    gap = np.empty(total)
    found = 0
    for p in range(len(a)):
        w, other = a[p], b[p]
        cx, cy, cz, r = centre[w, 0], centre[w, 1], centre[w, 2], radius[w]
        for i in range(start[other], start[other] + count[other]):
            dx, dy, dz = pos[i, 0] - cx, pos[i, 1] - cy, pos[i, 2] - cz
            g = math.sqrt(dx * dx + dy * dy + dz * dz) - rbound[i] - r
            if g < margin:
                who[found], body[found], gap[found] = w, i, g
                found += 1
    per = np.zeros(creatures, dtype=np.int64)
    for k in range(found):
        per[who[k]] += 1
    for k in range(found):
        w, i = who[k], body[k]
        if per[w] <= crowded_over:
            continue
        nearest = np.inf  # np.minimum.reduceat over the creature's own bodies (NaN sticks)
        for own in range(start[w], start[w] + count[w]):
            dx, dy, dz = pos[own, 0] - pos[i, 0], pos[own, 1] - pos[i, 1], pos[own, 2] - pos[i, 2]
            g = math.sqrt(dx * dx + dy * dy + dz * dz) - rbound[own]
            if g < nearest or g != g:
                nearest = g
            if nearest != nearest:
                break
        gap[k] = nearest - rbound[i]
    return who[:found], body[:found], gap[:found]


@njit(cache=True, nogil=True)
def spheres_within(
    centre: np.ndarray, radius: np.ndarray, a: np.ndarray, b: np.ndarray, margin: float
) -> np.ndarray:
    """(pairs,) bool: the spheres a[p] and b[p] (centres of any dimension) come within
    `margin` of each other; `pairs.spheres_within`'s numbers without its temporaries."""
    out = np.empty(len(a), dtype=np.bool_)
    for p in range(len(a)):
        i, j = a[p], b[p]
        total = 0.0
        for k in range(centre.shape[1]):
            d = centre[i, k] - centre[j, k]
            total += d * d
        out[p] = math.sqrt(total) - (radius[i] + radius[j]) < margin
    return out


@njit(cache=True, nogil=True)
def kept_within(
    centre: np.ndarray,
    radius: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    offsets: np.ndarray,
    among: np.ndarray,
    margin: float,
) -> tuple[np.ndarray, np.ndarray]:
    """`NearPairCache`'s answer from its kept pairs (a, b; sorted by a, creature c's run
    from offsets[c] to offsets[c + 1]): those whose first creature is `among` (bool per
    creature; empty: every creature) and whose spheres come within `margin`, in order;
    `pairs._runs_of` and `spheres_within`'s numbers in one pass, without their index
    arrays (a crowd of 10,000 asks several times a frame)."""
    n = offsets.shape[0] - 1
    every = among.shape[0] == 0
    out_a = np.empty(len(a), dtype=np.int64)
    out_b = np.empty(len(a), dtype=np.int64)
    found = 0
    for c in range(n):
        if not every and not among[c]:
            continue
        for p in range(offsets[c], offsets[c + 1]):
            i, j = a[p], b[p]
            total = 0.0
            for k in range(centre.shape[1]):
                d = centre[i, k] - centre[j, k]
                total += d * d
            if math.sqrt(total) - (radius[i] + radius[j]) < margin:
                out_a[found], out_b[found] = i, j
                found += 1
    return out_a[:found], out_b[:found]


@njit(cache=True, nogil=True)
def largest_move(
    centre: np.ndarray, was_centre: np.ndarray, radius: np.ndarray, was_radius: np.ndarray
) -> float:
    """The most any sphere moved (centre) and grew (radius) since `was_*`: NaN if any
    number is NaN (`NearPairCache`'s validity test, without its temporaries)."""
    most = 0.0
    for i in range(len(radius)):
        total = 0.0
        for k in range(centre.shape[1]):
            d = centre[i, k] - was_centre[i, k]
            total += d * d
        grew = radius[i] - was_radius[i]
        moved = math.sqrt(total) + (0.0 if grew <= 0.0 else grew)  # NaN stays NaN
        if moved != moved:
            return moved
        if moved > most:
            most = moved
    return most


@njit(cache=True, nogil=True)
def dense_pairs(
    centre: np.ndarray, radius: np.ndarray, margin: float
) -> tuple[np.ndarray, np.ndarray]:
    """`pairs.near_pairs` of a small crowd (every pair compared): the ordered pairs (a, b),
    a != b, sorted by a then b, whose spheres come within `margin`; its numbers without
    its dozen passes over an (n, n) array."""
    n = centre.shape[0]
    a = np.empty(max(n * (n - 1), 0), dtype=np.int64)
    b = np.empty_like(a)
    found = 0
    for i in range(n):
        for j in range(n):
            if i == j:
                continue
            total = 0.0
            for k in range(centre.shape[1]):
                d = centre[i, k] - centre[j, k]
                total += d * d
            if math.sqrt(total) - (radius[i] + radius[j]) < margin:
                a[found], b[found] = i, j
                found += 1
    return a[:found], b[:found]
