"""The numba kernels of gait-clip replay: `GaitClips.evaluate` for K creatures in one pass
(into rows of (N, B) arrays, `place`, or into a batch's Transform store rows wherever
they are, `place_scattered`), each replayed creature turned and moved a frame on its way
(`steer`), and the clip frame each creature starts replaying from (`nearest_frames`).

Optional, as the fur rig's kernels are: `clips` imports this module only when numba is
installed (the ``dev`` extra brings it) and falls back to its whole-array numpy path
otherwise; both give the same poses to float64 rounding (tests/lod/test_clips.py).

The numpy path makes about twenty passes over (creatures, bodies) arrays (gather the
clip frame, interpolate, normalise, turn and move); at 10,000 kinematic creatures of
81 bodies that was about 60 ms a frame. Here each body is read once and written once,
and each creature's reach sphere (the contact proxies' and the level of detail's) can be
found from its bodies as they were just written, still in the cache (`_sphere`: the
contact proxies' numbers), which spares the next frame a pass over every replayed body
(`physics.posed_spheres.PosedSpheres`). Compiled on first use and cached on disk
(``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def place(
    pose: np.ndarray,
    change: np.ndarray,
    row: np.ndarray,
    fraction: np.ndarray,
    interpolate: bool,
    xy: np.ndarray,
    heading: np.ndarray,
    out_rows: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
    sphere_of: np.ndarray,
    start: np.ndarray,
    rbound: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """Creature k shows clip table row `row[k]` (+ `fraction[k]` of `change` when
    `interpolate`, quaternions renormalised) moved to `xy[k]` and turned by `heading[k]`,
    written to row `out_rows[k]` of the outputs (rows of a larger array: no copy after).

    `pose` and `change` are (rows, B, 7) ground-frame tables (position, quaternion);
    the outputs are (N, B, 3) and (N, B, 4). Unless `sphere_of` is empty, creature k's
    reach sphere goes to row `sphere_of[k]` of `out_centre` / `out_radius`, found from
    its bodies as written (`_sphere`; body b's bound is
    `rbound[start[sphere_of[k]] + b]`).
    """
    bodies = pose.shape[1]
    every = np.arange(bodies)  # body b of a creature's output row at row b
    for k in range(len(row)):
        r, o, t = row[k], out_rows[k], fraction[k]
        c, s = math.cos(heading[k]), math.sin(heading[k])
        hc, hs = math.cos(0.5 * heading[k]), math.sin(0.5 * heading[k])
        ox, oy = xy[k, 0], xy[k, 1]
        for b in range(pose.shape[1]):
            p = pose[r, b]
            x, y, z = p[0], p[1], p[2]
            w, qx, qy, qz = p[3], p[4], p[5], p[6]
            if interpolate:
                d = change[r, b]
                x, y, z = x + d[0] * t, y + d[1] * t, z + d[2] * t
                w, qx, qy, qz = w + d[3] * t, qx + d[4] * t, qy + d[5] * t, qz + d[6] * t
                norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
                w, qx, qy, qz = w / norm, qx / norm, qy / norm, qz / norm
            px, py = c * x - s * y + ox, s * x + c * y + oy
            qw, q1, q2, q3 = (
                hc * w - hs * qz,
                hc * qx - hs * qy,
                hc * qy + hs * qx,
                hc * qz + hs * w,
            )
            out_pos[o, b, 0], out_pos[o, b, 1], out_pos[o, b, 2] = px, py, z
            out_quat[o, b, 0], out_quat[o, b, 1], out_quat[o, b, 2], out_quat[o, b, 3] = (
                qw, q1, q2, q3,
            )  # fmt: skip
        if len(sphere_of):
            first = start[sphere_of[k]]
            bounds = rbound[first : first + bodies]
            _sphere(out_pos[o], every, bounds, sphere_of[k], out_centre, out_radius)


@njit(cache=True, nogil=True)
def place_scattered(
    pose: np.ndarray,
    change: np.ndarray,
    row: np.ndarray,
    fraction: np.ndarray,
    interpolate: bool,
    xy: np.ndarray,
    heading: np.ndarray,
    out_rows: np.ndarray,
    body_rows: np.ndarray,
    out_pos: np.ndarray,
    out_quat: np.ndarray,
    sphere_of: np.ndarray,
    start: np.ndarray,
    rbound: np.ndarray,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """`place` (the same numbers), body b of creature k written to row
    `body_rows[out_rows[k], b]` of `out_pos` (rows, 3) and `out_quat` (rows, 4): the
    Transform store, whose rows of a batch's bodies (`Batch.body_rows`, (N, B)) need
    not be consecutive."""
    bodies = pose.shape[1]
    for k in range(len(row)):
        r, o, t = row[k], out_rows[k], fraction[k]
        c, s = math.cos(heading[k]), math.sin(heading[k])
        hc, hs = math.cos(0.5 * heading[k]), math.sin(0.5 * heading[k])
        ox, oy = xy[k, 0], xy[k, 1]
        for b in range(pose.shape[1]):
            p = pose[r, b]
            x, y, z = p[0], p[1], p[2]
            w, qx, qy, qz = p[3], p[4], p[5], p[6]
            if interpolate:
                d = change[r, b]
                x, y, z = x + d[0] * t, y + d[1] * t, z + d[2] * t
                w, qx, qy, qz = w + d[3] * t, qx + d[4] * t, qy + d[5] * t, qz + d[6] * t
                norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
                w, qx, qy, qz = w / norm, qx / norm, qy / norm, qz / norm
            px, py = c * x - s * y + ox, s * x + c * y + oy
            qw, q1, q2, q3 = (
                hc * w - hs * qz,
                hc * qx - hs * qy,
                hc * qy + hs * qx,
                hc * qz + hs * w,
            )
            at = body_rows[o, b]
            out_pos[at, 0], out_pos[at, 1], out_pos[at, 2] = px, py, z
            out_quat[at, 0], out_quat[at, 1], out_quat[at, 2], out_quat[at, 3] = qw, q1, q2, q3
        if len(sphere_of):
            first = start[sphere_of[k]]
            bounds = rbound[first : first + bodies]
            _sphere(out_pos, body_rows[o], bounds, sphere_of[k], out_centre, out_radius)


@njit(cache=True, nogil=True, inline="always")
def _sphere(
    pos: np.ndarray,
    rows: np.ndarray,
    bounds: np.ndarray,
    c: int,
    out_centre: np.ndarray,
    out_radius: np.ndarray,
) -> None:
    """Creature c's reach sphere from its bodies at `pos[rows]` (its mantle first; body
    i's bounding radius `bounds[i]`): centre at the mantle, radius to the farthest body's
    surface. The contact proxies' `physics.kernels._sphere`, operation for operation
    (the same bits, tests/clips/test_replay.py): a copy, since numba's cache of a kernel
    does not notice an edit to a function of another module it inlines."""
    mantle = rows[0]
    cx, cy, cz = pos[mantle, 0], pos[mantle, 1], pos[mantle, 2]
    out_centre[c, 0], out_centre[c, 1], out_centre[c, 2] = cx, cy, cz
    radius = -np.inf
    for i in range(len(rows)):
        row = rows[i]
        dx, dy, dz = pos[row, 0] - cx, pos[row, 1] - cy, pos[row, 2] - cz
        reach = math.sqrt(dx * dx + dy * dy + dz * dz) + bounds[i]
        if reach > radius:
            radius = reach
    out_radius[c] = radius


@njit(cache=True, nogil=True)
def nearest_frames(shapes: np.ndarray, shape: np.ndarray, out: np.ndarray) -> None:
    """`replay._nearest_frame`: for each pose `shape[k]` (K, B, 3), the first frame f of
    `shapes` (F, B, 3) whose farthest body (Euclidean distance, summed as numpy's norm
    sums x, y, z) is nearest, into `out[k]`. A frame is left as soon as one of its bodies
    is as far as the best frame's farthest: it can no longer be strictly nearer, so the
    answer is numpy's `argmin` of the maxima. Finite inputs only."""
    for k in range(shape.shape[0]):
        best = np.inf
        found = 0
        for f in range(shapes.shape[0]):
            worst = -np.inf
            for b in range(shapes.shape[1]):
                dx = shape[k, b, 0] - shapes[f, b, 0]
                dy = shape[k, b, 1] - shapes[f, b, 1]
                dz = shape[k, b, 2] - shapes[f, b, 2]
                d = math.sqrt(dx * dx + dy * dy + dz * dz)
                if d > worst:
                    worst = d
                    if worst >= best:
                        break
            if worst < best:
                best = worst
                found = f
        out[k] = found


@njit(cache=True, nogil=True)
def steer(
    moving: np.ndarray,
    target: np.ndarray,
    batch_of: np.ndarray,
    speed: np.ndarray,
    advance: np.ndarray,
    dt: float,
    limit: float,
    arrived: float,
    crawl_kind: int,
    idle_kind: int,
    xy: np.ndarray,
    heading: np.ndarray,
    phase: np.ndarray,
    kind: np.ndarray,
) -> None:
    """`replay._steer_numpy` in one pass, creature by creature: creature `moving[k]`
    (target `target[k]`, nan: none; its batch `batch_of[k]`) crawls if farther than
    `arrived` from its target, turning toward it by at most `limit` and moving
    `speed[batch] * dt` along its new heading; its clip kind is set and its phase moves
    `advance[batch]` frames on. The same operations in the same order as numpy's
    (`angle(exp(1j * x))` is `atan2(sin x, cos x)`): tests/clips/test_replay.py."""
    for k in range(len(moving)):
        i = moving[k]
        wx = target[k, 0] - xy[i, 0]
        wy = target[k, 1] - xy[i, 1]
        distance = math.hypot(wx, wy)
        crawl = math.isfinite(distance) and distance > arrived
        h = heading[i]
        turned = 0.0
        if crawl:
            off = math.atan2(wy, wx) - h
            turned = min(max(math.atan2(math.sin(off), math.cos(off)), -limit), limit)
        h = h + turned
        heading[i] = h
        kind[i] = crawl_kind if crawl else idle_kind
        b = batch_of[k]
        step = (speed[b] if crawl else 0.0) * dt
        xy[i, 0] += step * math.cos(h)
        xy[i, 1] += step * math.sin(h)
        phase[i] += advance[b]
