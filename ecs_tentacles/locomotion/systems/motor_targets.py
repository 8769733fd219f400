"""motor_targets: joint targets and servo gains of every link, from actions and waves.

For every link at once: the pose of its tentacle's current action (a straight,
slightly tilted tentacle, drooping toward its tip so a tapering tentacle's
underside lies on the ground, or an arch for compress/pull: link pitch
-angle * sin(2 pi arc), flat at base and tip, which shortens the tentacle to about
J0(angle) of its length), the orient sweep on the first two joints, plus travelling sine waves
(amplitude, frequency, wavelength in tentacle lengths, per-tentacle phase) on curl
and sweep; targets ease toward that (time constant SMOOTHING_SECONDS) so light
tips never whip. Creatures the level of detail replays (KINEMATIC, as the last frame
decided: `PhysicsBackend.kinematic_creatures`) are skipped: their servos drive nothing.
Writhing (thesis IV.B): the servo gain is modulated by the same wave,
scaled by the action's strength.
On terrain every tentacle also follows the ground ahead (`ground_follow`): where the
surface under its reach falls away from the creature's own plane (a crest, a dip) or
rises into it (a step, the foot of a slope), its droop ramp bends the tip down or up
by that much, the way procedural legs probe the ground under each foot. On the plane
this term is never computed (the motion stays exactly the thesis's).
With numba installed, two kernels (`ecs_tentacles.locomotion.kernels`) do the per-link
math in one pass each, the same numbers bit for bit (the sines stay numpy's).

Reads: locomotion's tentacle store (action, action_angle, action_strength, orient,
mode, wave parameters), TentacleStore (rest pitch, link rows, creature), MotorStore
(tentacle_row, arc), the physics' tiers, on terrain the Transform store (mantle, base
and tip poses) and the Ground. Writes: MotorStore (target, gain).
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import Ground, ground_of
from ecs_tentacles.locomotion.actions import ATTACH_PATIENCE, GRIPPING, Kind, Mode
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

# Constant pitch (radians, positive = tip down) of each action's pose.
LIFT = np.zeros(len(Kind))
LIFT[[Kind.COMPRESS, Kind.EXTEND, Kind.ORIENT, Kind.DETACH]] = [-0.08, -0.1, -0.08, -0.12]
LIFT[Kind.ATTACH] = 0.0
ORIENTED = np.zeros(len(Kind), dtype=bool)
ORIENTED[
    [Kind.ORIENT, Kind.EXTEND, Kind.COMPRESS, Kind.ATTACH, Kind.PUSH, Kind.PULL, Kind.DETACH]
] = True
HALF_ROOT3 = np.sqrt(3.0) / 2.0
# Which (action, mode) pairs hold the arch pose.
ARCHED = np.zeros((len(Kind), len(Mode)), dtype=bool)
ARCHED[[Kind.COMPRESS, Kind.PULL], :] = True
ARCHED[Kind.ATTACH, Mode.PUSH] = True
ARCHED[Kind.DETACH, Mode.PULL] = True
ATTACH = int(Kind.ATTACH)
ATTACH_PRESS = 0.15  # extra tip-down pitch (at the tip) per attach duration without a grip
# While a tentacle grips, its vertical wave stops (the tip must stay on the ground)
# and its sideways wave quietens.
GRIP_CURL_WAVE, GRIP_SWEEP_WAVE = 0.0, 0.3
SMOOTHING_SECONDS = 0.06  # targets ease toward each new pose (slow-in) instead of jumping
FOLLOW_LIMIT = 0.8  # radians: the most the droop ramp bends to follow the ground
# numba's kernels when installed (the same numbers bit for bit; "numpy": never)
KERNELS = OptionalKernels("ecs_tentacles.locomotion.kernels", "ECS_TENTACLES_LOCOMOTION")
KERNEL_CONSTANTS = np.array(
    [ATTACH_PATIENCE, ATTACH_PRESS, GRIP_CURL_WAVE, GRIP_SWEEP_WAVE, HALF_ROOT3]
)
NO_FOLLOW = np.zeros(0)


def ground_follow(world: Host, ground: Ground, rows: np.ndarray) -> np.ndarray:
    """(len(rows),) extra droop (radians, positive: tip down) that brings tentacle
    `rows`' reach onto the ground: the tip of the tentacle stretched along its creature's
    plane would be `gap` above the surface; a droop ramp of 2 atan(gap / length) lowers
    it so."""
    t, pos = world.tentacles, world.transforms.pos
    length = t.length[rows]
    mantles = world.creatures.mantle_row[t.creature_row[rows]]
    tips = t.base_row[rows] + t.links[rows] - 1
    fast = KERNELS.get()
    if fast is not None:  # the same points in one pass
        reach = np.empty((len(rows), 3))
        fast.follow_reach(pos, world.transforms.quat, mantles, t.base_row[rows], tips, length,
                          reach)  # fmt: skip
    else:
        up = np.zeros((len(rows), 3))
        up[:, 2] = 1.0
        up = quat_rotate(world.transforms.quat[mantles], up)
        base = pos[t.base_row[rows]]
        along = pos[tips] - base
        along -= np.sum(along * up, axis=1, keepdims=True) * up
        along /= np.maximum(np.linalg.norm(along, axis=1, keepdims=True), 1e-9)
        reach = base + length[:, None] * along
    gap = ground.distance(reach)
    follow: np.ndarray = np.clip(2.0 * np.arctan2(gap, length), -FOLLOW_LIMIT, FOLLOW_LIMIT)
    return follow


class MotorTargets(System):
    name = "motor_targets"
    stage = "act"
    after = ("action_queue",)
    reads = (
        "locomotion.tentacles",
        "tentacles.rest_pitch",
        "tentacles.first_link",
        "tentacles.links",
        "tentacles.creature_row",
        "motors.arc",
        "motors.tentacle_row",
    )
    writes = ("motors.target", "motors.gain")
    state_attributes = ("eased",)

    def setup(self, world: Host) -> None:
        motors, tentacles = world.motors, world.tentacles
        rows = np.arange(len(motors))
        first = tentacles.first_link
        inner = np.ones(len(motors), dtype=bool)
        inner[first] = False
        self.inner = rows[inner]  # links whose joint turns relative to a previous link
        self.previous = self.inner - 1
        self.previous_of = np.where(inner, rows - 1, -1)  # per link: the one before, or -1
        self.orient_share = np.zeros(len(motors))
        self.orient_share[first] = 0.5
        self.orient_share[np.minimum(first + 1, first + tentacles.links - 1)] += 0.5
        self.arch_shape = np.sin(2 * np.pi * motors.arc)
        # the eased targets live here, so systems that add to Motor.target after this one
        # (user waves, the HUD) do not feed back into the easing
        self.eased = motors.target[:, :2].copy()
        self.strokes = world.resource(LocomotionStores).tentacles
        self.follow: np.ndarray | None = None  # on terrain: `ground_follow` this frame

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """A spawn: the tables made again, everyone's easing kept; a despawn: the removed
        links' entries dropped and the rest renumbered (what `setup` would make)."""
        moved = change.moved.get("motors")
        if not change.spawned:
            if moved is None:
                return
            keep = moved >= 0
            self.eased = self.eased[keep]
            self.arch_shape, self.orient_share = self.arch_shape[keep], self.orient_share[keep]
            before = self.previous_of[keep]  # a link's previous one goes with it, or stays
            self.previous_of = np.where(before >= 0, moved[before], -1)
            self.inner = np.flatnonzero(self.previous_of >= 0)
            self.previous = self.previous_of[self.inner]
            return
        eased = change.follow(self.eased, "motors")
        self.setup(world)
        self.eased = eased
        added = change.added.get("motors", slice(0))
        self.eased[added] = world.motors.target[added, :2]

    def process(self, world: Host, dt: float) -> None:
        motors = world.motors
        if not len(motors):
            return
        ground = ground_of(world)
        kinematic = world.physics.kinematic_creatures(len(world.creatures))
        self.follow = None
        if not ground.flat:  # for the tentacles the physics drives (kinematic ones replay)
            driven = np.flatnonzero(~kinematic[world.tentacles.creature_row])
            self.follow = np.zeros(len(world.tentacles))
            self.follow[driven] = ground_follow(world, ground, driven)
        if not kinematic.any():
            self._targets(world, dt, slice(None))
            return
        # creatures the level of detail replays: their servos drive nothing, so their
        # links are left out (a promoted one eases from its last targets, servos soft)
        links = _links_of(world, np.flatnonzero(~kinematic[world.tentacles.creature_row]))
        if len(links):
            self._targets(world, dt, links)

    def _targets(self, world: Host, dt: float, links: slice | np.ndarray) -> None:
        """The targets and gains of motor rows `links`: every row, or whole tentacles."""
        fast = KERNELS.get()
        if fast is not None:
            self._kernel_targets(fast, world, dt, links)
            return
        if isinstance(links, slice):
            inner, previous = self.inner, self.previous
        else:
            # whole tentacles, each a run of consecutive rows in `links`: an inner link's
            # previous one is the entry before it (no table over every motor row)
            inner = np.flatnonzero(self.previous_of[links] >= 0)
            previous = inner - 1
        motors, t, body = world.motors, self.strokes, world.tentacles
        row = motors.tentacle_row[links]
        arc = motors.arc[links]
        action = t.action
        # per tentacle (few rows) where it saves work, then gathered to every link
        progress = np.minimum(t.timer / np.maximum(t.duration, 1e-9), ATTACH_PATIENCE)
        # the arch rises from a flat base, peaks mid-way and comes down to a flat tip;
        # the base lies on the ground and cannot tilt down, so tip-down bends are ramps
        # along the tentacle: the rest droop, and an attaching tip pressing down further
        # the longer it takes to touch the ground
        arch = np.where(ARCHED[action, t.mode], -t.action_angle, 0.0)[row]
        droop = 2.0 * body.rest_pitch + np.where(action == ATTACH, ATTACH_PRESS * progress, 0.0)
        if self.follow is not None:
            droop = droop + self.follow
        droop = droop[row]
        pitch = arch * self.arch_shape[links] + LIFT[action][row] + droop * arc
        curl = pitch.copy()
        curl[inner] -= pitch[previous]
        sweep = np.where(ORIENTED[action], t.orient, 0.0)[row] * self.orient_share[links]

        phase = (2 * np.pi * t.wave_frequency * world.time + t.phase)[row] - (
            2 * np.pi / t.wavelength
        )[row] * arc
        sin, cos = np.sin(phase), np.cos(phase)
        gripping = GRIPPING[action]
        amplitude = t.wave_amplitude
        curl_amp = (amplitude * np.where(gripping, GRIP_CURL_WAVE, 1.0))[row]
        sweep_amp = (amplitude * np.where(gripping, GRIP_SWEEP_WAVE, 1.0))[row]
        ease = 1.0 - np.exp(-dt / SMOOTHING_SECONDS)
        eased = self.eased[links]  # a view of every row, or a copy of some (written back)
        eased[:, 0] += ease * (curl + curl_amp * sin - eased[:, 0])
        eased[:, 1] += ease * (sweep + sweep_amp * cos - eased[:, 1])
        self.eased[links] = eased
        motors.target[links, :2] = eased
        # writhing: sin(phase + pi/3), from the sine and cosine already at hand
        strength = t.action_strength
        gain = strength[row] + (strength * t.writhe)[row] * (0.5 * sin + HALF_ROOT3 * cos)
        motors.gain[links] = gain

    def _kernel_targets(
        self, fast: ModuleType, world: Host, dt: float, links: slice | np.ndarray
    ) -> None:
        """`_targets` by `ecs_tentacles.locomotion.kernels` (whole tentacles `links`)."""
        motors, t = world.motors, self.strokes
        rows = np.arange(len(motors)) if isinstance(links, slice) else links
        row, arc = motors.tentacle_row, motors.arc
        phase = np.empty(len(rows))
        fast.wave_phase(world.time, t.wave_frequency, t.phase, t.wavelength, row, arc, rows, phase)
        sin, cos = np.sin(phase), np.cos(phase)
        ease = float(1.0 - np.exp(-dt / SMOOTHING_SECONDS))
        follow = NO_FOLLOW if self.follow is None else self.follow
        fast.targets(
            rows, self.previous_of, row, arc, self.arch_shape, self.orient_share,
            t.action, t.mode, t.timer, t.duration, t.action_angle,
            world.tentacles.rest_pitch, follow, t.orient, t.wave_amplitude,
            t.action_strength, t.writhe, ARCHED, LIFT, ORIENTED, GRIPPING, ATTACH,
            KERNEL_CONSTANTS, sin, cos, ease, self.eased, motors.target, motors.gain,
        )  # fmt: skip


def _links_of(world: Host, tentacles: np.ndarray) -> np.ndarray:
    """The motor rows of tentacle rows `tentacles`, ascending (each tentacle's links are
    the consecutive rows from its first): work for these tentacles, not for every motor."""
    t = world.tentacles
    order = tentacles[np.argsort(t.first_link[tentacles], kind="stable")]
    first, count = t.first_link[order], t.links[order]
    starts = np.repeat(first - (np.cumsum(count) - count), count)
    return starts + np.arange(int(count.sum()))
