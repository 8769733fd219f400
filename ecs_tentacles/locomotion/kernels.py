"""The numba kernels of `motor_targets` (the travelling waves' phases, then every link's
eased targets and writhing gain): one pass over the links each, where the numpy path
takes some forty whole-array operations of a few microseconds each.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): the
system imports this module only when numba is installed and falls back to numpy
otherwise. Both compute the same numbers bit for bit: the same operations in the same
order, the sines and cosines taken by numpy in both (numba may vectorise them with
other libraries), no fused multiply-adds (numba contracts only with `fastmath`).
tests/locomotion/systems/test_motor_targets.py compares the two.
"""

from __future__ import annotations

import numpy as np
from numba import njit

TWO_PI = 2 * np.pi  # as numpy's path has it: `2 * np.pi * frequency`, `2 * np.pi / wavelength`


@njit(cache=True, nogil=True)
def wave_phase(
    time: float,
    frequency: np.ndarray,
    phase: np.ndarray,
    wavelength: np.ndarray,
    row: np.ndarray,
    arc: np.ndarray,
    links: np.ndarray,
    out: np.ndarray,
) -> None:
    """`out[i]`: the travelling wave's phase at motor row `links[i]` (tentacle `row[l]`,
    arc position `arc[l]`) at world time `time`."""
    for i in range(len(links)):
        link = links[i]
        t = row[link]
        out[i] = (TWO_PI * frequency[t] * time + phase[t]) - (TWO_PI / wavelength[t]) * arc[link]


@njit(cache=True, nogil=True)
def _pitch(
    link: int,
    t: int,
    arch: float,
    lift: float,
    droop: float,
    arch_shape: np.ndarray,
    arc: np.ndarray,
) -> float:
    """Link `link`'s pose pitch: its tentacle's arch, lift and droop ramp at its arc."""
    pitch: float = arch * arch_shape[link] + lift + droop * arc[link]
    return pitch


@njit(cache=True, nogil=True)
def targets(
    links: np.ndarray,
    previous_of: np.ndarray,
    row: np.ndarray,
    arc: np.ndarray,
    arch_shape: np.ndarray,
    orient_share: np.ndarray,
    action: np.ndarray,
    mode: np.ndarray,
    timer: np.ndarray,
    duration: np.ndarray,
    action_angle: np.ndarray,
    rest_pitch: np.ndarray,
    follow: np.ndarray,
    orient: np.ndarray,
    amplitude: np.ndarray,
    strength: np.ndarray,
    writhe: np.ndarray,
    arched: np.ndarray,
    lift_of: np.ndarray,
    oriented: np.ndarray,
    gripping: np.ndarray,
    attach: int,
    constants: np.ndarray,
    sin: np.ndarray,
    cos: np.ndarray,
    ease: float,
    eased: np.ndarray,
    target: np.ndarray,
    gain: np.ndarray,
) -> None:
    """Eased (curl, sweep) targets and writhing gains of motor rows `links` (whole
    tentacles; `sin[i]`, `cos[i]` of link `links[i]`'s wave phase): into `eased`,
    `target[:, :2]` and `gain`. `follow` is empty on the plane; `attach` is the attach
    action's code (its tip presses down); `constants` = (attach patience, attach press,
    curl wave and sweep wave while gripping, sqrt(3) / 2)."""
    patience, press, grip_curl, grip_sweep, half_root3 = (
        constants[0], constants[1], constants[2], constants[3], constants[4]
    )  # fmt: skip
    for i in range(len(links)):
        link = links[i]
        t = row[link]
        kind = action[t]
        arch = -action_angle[t] if arched[kind, mode[t]] else 0.0
        duration_t = duration[t]
        if duration_t < 1e-9:
            duration_t = 1e-9
        progress = timer[t] / duration_t
        if progress > patience:
            progress = patience
        droop = 2.0 * rest_pitch[t] + (press * progress if kind == attach else 0.0)
        if len(follow):
            droop = droop + follow[t]
        lift = lift_of[kind]
        curl = _pitch(link, t, arch, lift, droop, arch_shape, arc)
        before = previous_of[link]
        if before >= 0:
            curl -= _pitch(before, t, arch, lift, droop, arch_shape, arc)
        sweep = (orient[t] if oriented[kind] else 0.0) * orient_share[link]
        curl_amp = amplitude[t] * (grip_curl if gripping[kind] else 1.0)
        sweep_amp = amplitude[t] * (grip_sweep if gripping[kind] else 1.0)
        e0, e1 = eased[link, 0], eased[link, 1]
        e0 += ease * (curl + curl_amp * sin[i] - e0)
        e1 += ease * (sweep + sweep_amp * cos[i] - e1)
        eased[link, 0], eased[link, 1] = e0, e1
        target[link, 0], target[link, 1] = e0, e1
        gain[link] = strength[t] + strength[t] * writhe[t] * (0.5 * sin[i] + half_root3 * cos[i])


@njit(cache=True, nogil=True)
def follow_reach(
    pos: np.ndarray,
    quat: np.ndarray,
    mantles: np.ndarray,
    bases: np.ndarray,
    tips: np.ndarray,
    length: np.ndarray,
    out: np.ndarray,
) -> None:
    """`ground_follow`'s reach points: for tentacle i, its base (store row bases[i]) plus
    length[i] along base -> tip (tips[i]) laid onto its mantle's (mantles[i]) plane, the
    mantle's up being its quaternion turning (0, 0, 1) as `quat_rotate` does."""
    for i in range(bases.shape[0]):
        m = mantles[i]
        w, x, y, z = quat[m, 0], quat[m, 1], quat[m, 2], quat[m, 3]
        t0 = 2.0 * (y * 1.0 - z * 0.0)
        t1 = 2.0 * (z * 0.0 - x * 1.0)
        t2 = 2.0 * (x * 0.0 - y * 0.0)
        u0 = 0.0 + w * t0 + (y * t2 - z * t1)
        u1 = 0.0 + w * t1 + (z * t0 - x * t2)
        u2 = 1.0 + w * t2 + (x * t1 - y * t0)
        b, t = bases[i], tips[i]
        a0, a1, a2 = pos[t, 0] - pos[b, 0], pos[t, 1] - pos[b, 1], pos[t, 2] - pos[b, 2]
        along = (a0 * u0 + a1 * u1) + a2 * u2
        a0, a1, a2 = a0 - along * u0, a1 - along * u1, a2 - along * u2
        size = np.sqrt((a0 * a0 + a1 * a1) + a2 * a2)
        if not (size >= 1e-9 or size != size):  # np.maximum(size, 1e-9): NaN kept
            size = 1e-9
        a0, a1, a2 = a0 / size, a1 / size, a2 / size
        out[i, 0] = pos[b, 0] + length[i] * a0
        out[i, 1] = pos[b, 1] + length[i] * a1
        out[i, 2] = pos[b, 2] + length[i] * a2
