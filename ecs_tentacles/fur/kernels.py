"""Numba kernels of the rig: the same math as `ecs_tentacles.fur.rig`, guide by guide.

Optional: `rig` imports this module only when numba is installed (the ``dev`` extra
brings it) and falls back to its whole-array numpy path otherwise; both give the
same frames within float32 rounding (tests/fur/test_rig_kernels.py checks it).

numpy is slow where the rig's data changes layout (per-guide 3x3 products, the
(n, 4, 3) frames and the (n, points, 3) curves), numba where it calls transcendental
functions one value at a time. So a block of guides goes through three passes:

1. `blend` (numba): each guide's blended direction (aim, direction) in its skin
   coordinates, the inputs of the lift's angle and the twist angle;
2. numpy: arctan2, sin and cos of whole arrays (vectorised, several times faster);
3. `frames` (numba): lift, twist, side and up, the skin -> body -> world turn, the
   frames written in (n, 4, 3) rows and the curves posed from them (as `pose` does).

Kernels compute in float32 (as the numpy path does), guide by guide, and branch
only on what is the same for every guide: a behaviour no control uses contributes
exact zeros. Each kernel is compiled twice: on all cores (``prange``, numba's
OpenMP pool) and serially (`<name>_serial`). The parallel ones pay only for large
furs: below `rig.PARALLEL_GUIDES` guides the pool's start-up and its spinning
threads cost more than they save, and they take cores from the physics threads.
They are compiled on first use and cached on disk (``cache=True``), so only the
first run after an install or an edit pays the compile time (about 20 s on the
2-core machine).

`strands` is the dynamic blend's strand step (`dynamics.Strands.step`), the same
float32 operations in the same order, one guide at a time.
"""

from __future__ import annotations

import math
import os
import types
from collections.abc import Callable
from typing import Any

import numpy as np

# OpenMP's worker threads (numba's "omp" layer) spin after each parallel kernel by
# default, taking the cores from the physics threads; passive ones sleep. Read when
# numba first starts its pool, so set before any parallel kernel runs.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from numba import njit, prange

ONE = np.float32(1.0)
ZERO = np.float32(0.0)
TINY = np.float32(1e-12)
UNLIFT, KEEP, TWIST = 0, 1, 2  # rows of `rig.control_table`
AIM_X, DIRECTION_X, AIM_WEIGHT, DIRECTION_WEIGHT = 3, 4, 9, 10
TINY_LINK = np.float32(1e-12)
STRAND_CHUNK = 512  # strands a parallel task takes (a few cache lines per row each)


def _compiled(func: Callable[..., Any]) -> tuple[Any, Any]:
    """`func` compiled for all cores and serially; distinct names keep their caches apart."""
    serial = types.FunctionType(
        func.__code__, func.__globals__, f"{func.__name__}_serial", func.__defaults__
    )
    serial.__qualname__ = f"{func.__qualname__}_serial"
    return (
        njit(cache=True, nogil=True, parallel=True)(func),
        njit(cache=True, nogil=True)(serial),
    )


@njit(cache=True, nogil=True, inline="always")
def _capped(
    vx: np.float32, vy: np.float32, vz: np.float32, tan_min: np.float32, weight: np.float32
) -> tuple[np.float32, np.float32, np.float32]:
    """weight * unit(clamp(unit(v))): `rig.clamp_to_cap` in skin coordinates, weighted."""
    length = math.sqrt(vx * vx + vy * vy + vz * vz)
    inv = ONE / (length if length > TINY else TINY)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    vz = vz if vz > tan_min else tan_min
    length = math.sqrt(vx * vx + vy * vy + vz * vz)
    scale = weight / (length if length > TINY else TINY)
    return vx * scale, vy * scale, vz * scale


def _blend(
    control: np.ndarray,
    table: np.ndarray,
    rest_cos: np.ndarray,
    rest_sin: np.ndarray,
    tan_min: np.ndarray,
    multiplier: np.ndarray,
    basis: np.ndarray,
    root: np.ndarray,
    normalise: bool,
    axis: np.ndarray,
    flat: np.ndarray,
    unlift: np.ndarray,
    angle: np.ndarray,
) -> None:
    """Pass 1: blended axis (3, n) in skin coordinates; lift and twist inputs (n,).

    `normalise`: make the blend a unit vector (when no lift does it).
    """
    for g in prange(len(control)):
        c = control[g]
        x0, z0, cap = rest_cos[g], rest_sin[g], tan_min[g]
        b00, b01, b02 = basis[0, 0, g], basis[0, 1, g], basis[0, 2, g]
        b10, b11, b12 = basis[1, 0, g], basis[1, 1, g], basis[1, 2, g]
        b20, b21, b22 = basis[2, 0, g], basis[2, 1, g], basis[2, 2, g]
        # aim: root -> control, in skin axes
        dx = table[AIM_X, c] - root[0, g]
        dy = table[AIM_X + 2, c] - root[1, g]
        dz = table[AIM_X + 4, c] - root[2, g]
        vx = b00 * dx + b01 * dy + b02 * dz
        vy = b10 * dx + b11 * dy + b12 * dz
        vz = b20 * dx + b21 * dy + b22 * dz
        ax, ay, az = _capped(vx, vy, vz, cap, table[AIM_WEIGHT, c])
        # direction: the rest direction reaching `reach`, plus the control's offset
        dx = table[DIRECTION_X, c]
        dy = table[DIRECTION_X + 2, c]
        dz = table[DIRECTION_X + 4, c]
        vx = b00 * dx + b01 * dy + b02 * dz + x0
        vy = b10 * dx + b11 * dy + b12 * dz
        vz = b20 * dx + b21 * dy + b22 * dz + z0
        ox, oy, oz = _capped(vx, vy, vz, cap, table[DIRECTION_WEIGHT, c])
        keep = table[KEEP, c]
        x = (ax + ox) + keep * x0
        y = ay + oy
        z = (az + oz) + keep * z0
        length = math.sqrt(x * x + y * y + z * z)
        inv = ONE / (length if length > TINY else TINY)
        scale = inv if normalise else ONE
        x, y, z = x * scale, y * scale, z * scale
        axis[0, g] = x
        axis[1, g] = y
        axis[2, g] = z
        flat[g] = math.sqrt(x * x + y * y)
        unlift[g] = table[UNLIFT, c]
        angle[g] = table[TWIST, c] * multiplier[g]


@njit(cache=True, nogil=True, inline="always")
def _pose_guide(shape_h: np.ndarray, frames: np.ndarray, out: np.ndarray, g: int) -> None:
    """Guide g's points: rest-frame coordinates x its world frame (float32, fixed order)."""
    for p in range(shape_h.shape[1]):
        x, y, z = shape_h[g, p, 0], shape_h[g, p, 1], shape_h[g, p, 2]
        for i in range(3):
            out[g, p, i] = (
                x * frames[g, 0, i] + y * frames[g, 1, i] + z * frames[g, 2, i] + frames[g, 3, i]
            )


def _frames(
    axis: np.ndarray,
    flat: np.ndarray,
    polar_sin: np.ndarray,
    polar_cos: np.ndarray,
    twist_cos: np.ndarray,
    twist_sin: np.ndarray,
    lifting: bool,
    twisting: bool,
    basis: np.ndarray,
    root: np.ndarray,
    body: np.ndarray,
    rotation: np.ndarray,
    position: np.ndarray,
    local: np.ndarray,
    world: np.ndarray,
    shape_h: np.ndarray,
    curves: np.ndarray,
) -> None:
    """Pass 3: lift, twist, side, up; body-local frames (4, 3, n) into `local` and/or
    world frames (n, 4, 3) into `world`, posed into `curves` (n, points, 3) (a
    zero-length array skips any of them)."""
    want_local = local.shape[2] > 0
    want_world = world.shape[0] > 0
    want_curves = curves.shape[0] > 0
    for g in prange(axis.shape[1]):
        x, y, z = axis[0, g], axis[1, g], axis[2, g]
        # lift: the polar angle shrunk by `lift`, the azimuth kept
        lengthwise = flat[g]
        scale = polar_sin[g] / (lengthwise if lengthwise > TINY else TINY)
        x = x * scale if lifting else x
        y = y * scale if lifting else y
        z = polar_cos[g] if lifting else z
        k = y  # the axis's part along the rest side: a twist about the normal keeps it
        co = twist_cos[g] if twisting else ONE
        si = twist_sin[g] if twisting else ZERO
        x, y = x * co - y * si, x * si + y * co
        rest = ONE - k * k
        inv = ONE / math.sqrt(rest if rest > TINY else TINY)
        sx, sy, sz = (-si - k * x) * inv, (co - k * y) * inv, -k * z * inv
        ux, uy, uz = y * sz - z * sy, z * sx - x * sz, x * sy - y * sx
        b00, b01, b02 = basis[0, 0, g], basis[0, 1, g], basis[0, 2, g]
        b10, b11, b12 = basis[1, 0, g], basis[1, 1, g], basis[1, 2, g]
        b20, b21, b22 = basis[2, 0, g], basis[2, 1, g], basis[2, 2, g]
        a0, a1, a2 = (
            x * b00 + y * b10 + z * b20,
            x * b01 + y * b11 + z * b21,
            x * b02 + y * b12 + z * b22,
        )
        u0, u1, u2 = (
            ux * b00 + uy * b10 + uz * b20,
            ux * b01 + uy * b11 + uz * b21,
            ux * b02 + uy * b12 + uz * b22,
        )
        s0, s1, s2 = (
            sx * b00 + sy * b10 + sz * b20,
            sx * b01 + sy * b11 + sz * b21,
            sx * b02 + sy * b12 + sz * b22,
        )
        r0, r1, r2 = root[0, g], root[1, g], root[2, g]
        if want_local:
            local[0, 0, g], local[0, 1, g], local[0, 2, g] = a0, a1, a2
            local[1, 0, g], local[1, 1, g], local[1, 2, g] = u0, u1, u2
            local[2, 0, g], local[2, 1, g], local[2, 2, g] = s0, s1, s2
            local[3, 0, g], local[3, 1, g], local[3, 2, g] = r0, r1, r2
        if want_world:
            b = body[g]
            for i in range(3):
                m0, m1, m2 = rotation[b, i, 0], rotation[b, i, 1], rotation[b, i, 2]
                world[g, 0, i] = m0 * a0 + m1 * a1 + m2 * a2
                world[g, 1, i] = m0 * u0 + m1 * u1 + m2 * u2
                world[g, 2, i] = m0 * s0 + m1 * s1 + m2 * s2
                world[g, 3, i] = (m0 * r0 + m1 * r1 + m2 * r2) + position[b, i]
            if want_curves:
                _pose_guide(shape_h, world, curves, g)


def _pose(shape_h: np.ndarray, frames: np.ndarray, out: np.ndarray) -> None:
    """World points (n, points, 3): rest-frame coordinates x world frame, guide by guide."""
    for g in prange(shape_h.shape[0]):
        _pose_guide(shape_h, frames, out, g)


def _strands(
    pos: np.ndarray,
    prev: np.ndarray,
    fresh: np.ndarray,
    curves: np.ndarray,
    frames: np.ndarray,
    rows: np.ndarray,
    normal: np.ndarray,
    weight: np.ndarray,
    keep: np.ndarray,
    pull: np.ndarray,
    gravity: np.ndarray,
    segment: np.ndarray,
    profile: np.ndarray,
) -> None:
    """One Verlet step of the strands toward the rig's curves, blended in place.

    `pos`, `prev` (points, 3, m) and `fresh` (m,) are `Strands`' state; strand g is
    guide `rows[g]` of `curves` (n, points, 3) and `frames` (n, 4, 3), whose rig
    curve it reads and whose blended curve it writes back; `normal` (3, m) is world
    space, `profile` (points,). Chunks of `STRAND_CHUNK` strands go in parallel;
    inside a chunk the strands are the innermost loop, so the state is read in
    order. The float32 operations are `Strands.step`'s, in the same order.
    """
    points, m = pos.shape[0], pos.shape[2]
    for chunk in prange((m + STRAND_CHUNK - 1) // STRAND_CHUNK):
        # loops over 0..count on slices of the chunk (not lo..hi): numba then knows
        # the indices are not negative, and the compiler vectorises the loops
        lo = chunk * STRAND_CHUNK
        hi = min(lo + STRAND_CHUNK, m)
        count = hi - lo
        rig = np.empty((points, 3, count), dtype=np.float32)
        root = np.empty((3, count), dtype=np.float32)
        kept, pulled, blend, new = keep[lo:hi], pull[lo:hi], weight[lo:hi], fresh[lo:hi]
        chunk_rows = rows[lo:hi]
        for j in range(count):
            r = chunk_rows[j]
            for i in range(3):
                root[i, j] = frames[r, 3, i]
            for p in range(points):
                for i in range(3):
                    rig[p, i, j] = curves[r, p, i]
            if new[j]:  # first frame of this strand: start at rest on the rig
                for p in range(points):
                    for i in range(3):
                        pos[p, i, lo + j] = rig[p, i, j]
                        prev[p, i, lo + j] = rig[p, i, j]
                new[j] = False
        for p in range(points):
            for i in range(3):
                x, before, fall = pos[p, i, lo:hi], prev[p, i, lo:hi], gravity[i, lo:hi]
                target = rig[p, i]
                for j in range(count):
                    velocity = (x[j] - before[j]) * kept[j]
                    before[j] = x[j]
                    x[j] = x[j] + velocity + fall[j]
                for j in range(count):
                    x[j] = x[j] + (target[j] - x[j]) * pulled[j]
        for i in range(3):
            start = pos[0, i, lo:hi]
            for j in range(count):
                start[j] = rig[0, i, j]
        nx, ny, nz = normal[0, lo:hi], normal[1, lo:hi], normal[2, lo:hi]
        ox, oy, oz = root[0], root[1], root[2]
        for k in range(1, points):  # follow the leader; never below the root's plane
            x0, y0, z0 = pos[k - 1, 0, lo:hi], pos[k - 1, 1, lo:hi], pos[k - 1, 2, lo:hi]
            x1, y1, z1 = pos[k, 0, lo:hi], pos[k, 1, lo:hi], pos[k, 2, lo:hi]
            length_k = segment[k, lo:hi]
            for j in range(count):
                lx = x1[j] - x0[j]
                ly = y1[j] - y0[j]
                lz = z1[j] - z0[j]
                length = math.sqrt(lx * lx + ly * ly + lz * lz)
                scale = length_k[j] / (length if length > TINY_LINK else TINY_LINK)
                px = x0[j] + lx * scale
                py = y0[j] + ly * scale
                pz = z0[j] + lz * scale
                below = (px - ox[j]) * nx[j]
                below += (py - oy[j]) * ny[j]
                below += (pz - oz[j]) * nz[j]
                below = below if below < ZERO else ZERO
                x1[j] = px - below * nx[j]
                y1[j] = py - below * ny[j]
                z1[j] = pz - below * nz[j]
        for j in range(count):
            r = chunk_rows[j]
            for p in range(points):
                share = profile[p] * blend[j]
                for i in range(3):
                    x = rig[p, i, j]
                    curves[r, p, i] = (pos[p, i, lo + j] - x) * share + x


blend, blend_serial = _compiled(_blend)
frames, frames_serial = _compiled(_frames)
pose, pose_serial = _compiled(_pose)
strands, strands_serial = _compiled(_strands)
