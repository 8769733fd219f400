"""tentacle_selection: which tentacles drive, and whether each pushes or pulls.

Push or pull follows the thesis: compare the unit vectors mantle -> goal and
mantle -> tentacle base (in the ground plane); an angle within +-pi/2 (dot >= 0)
means the tentacle lies between mantle and goal: pull; otherwise push. On the plane
the ground plane is world xy; on terrain it is the plane of the surface under each
mantle (`ground_plane`): vectors are projected onto it, so a creature on a slope or a
ramp chooses and orients its strokes along the slope, not along their shadows.

* cyclic gait (the thesis): one driving tentacle at a time, in turn; a tentacle
  classifies itself only when its stroke is queued.
* coordinated gait (the thesis's future work): up to `drivers` tentacles at once,
  started out of phase; the next driver is the idle tentacle nearest the goal line
  (largest |cos|), pulls preferred; each first orients its base toward the goal
  direction; drivers are re-classified every frame and abort when the goal has moved
  to their other side.
* no goal: drives stop (the sucker lets go) and every tentacle idles.
* replayed creatures (KINEMATIC, as the last frame decided) start and abort nothing:
  their tentacles drive nothing, the gait clip carries them; a promoted creature
  picks up its strokes where they paused.

First it has the `Navigator` set each creature's steer point: its goal, or the next
waypoint of a path around obstacles (`ecs_tentacles.locomotion.navigation`). The
direction toward it is turned by the crowd-avoidance term the avoidance system wrote
(`ecs_tentacles.locomotion.avoidance.bent`; zero, and so no change, where no other
creature is near): that is the "goal" direction every choice below is made against.

Reads: locomotion's stores (goal, navigate, steer, avoidance; gait, drivers, speed; action,
mode, driving),
CreatureStore and TentacleStore (mantle, tentacle rows, bases), Transform store, the
Ground, the physics' tiers.
Writes: locomotion's tentacle store (driving, mode, started) and creature store
(steer, next_driver, last_start), ActionQueues (a started drive is queued and
the current action interrupted; an abort replaces the queue with detach, settle).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DESTINATIONS_READ
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.actions import (
    BASE_SECONDS,
    ActionQueues,
    Kind,
    Mode,
    drive_sequence,
)
from ecs_tentacles.locomotion.actions import make_action as action
from ecs_tentacles.locomotion.avoidance import bent
from ecs_tentacles.locomotion.navigation import Navigator
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.quaternions import cross
from ecs_tentacles.scene.parameters import parameter
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

KERNELS = OptionalKernels("ecs_tentacles.locomotion.selection_kernels", "ECS_TENTACLES_SELECTION")
PULL = int(Mode.PULL)
PULL_TOLERANCE = 1e-9  # dot products this close to 0 count as the +-pi/2 boundary: pull
ABORT_MARGIN = 0.25  # coordinated drivers abort once cos is this far on the wrong side
PUSH_PREFERENCE = 0.8  # pulls grip better than pushes
MIN_SCORE = 0.2
STROKE_SECONDS = sum(BASE_SECONDS[k] for k in (Kind.ORIENT, Kind.EXTEND, Kind.ATTACH, Kind.PULL))


def classify(to_goal: np.ndarray, to_base: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(pull, cos) per row: the thesis's test on (n, 2) ground-plane vectors mantle -> goal
    and mantle -> tentacle base (any lengths); pull where their angle is within +-pi/2."""
    dot = to_goal[:, 0] * to_base[:, 0] + to_goal[:, 1] * to_base[:, 1]
    lengths = np.hypot(to_goal[:, 0], to_goal[:, 1]) * np.hypot(to_base[:, 0], to_base[:, 1])
    cos = dot / np.maximum(lengths, 1e-12)
    return cos >= -PULL_TOLERANCE, cos


def ground_plane(normals: np.ndarray) -> np.ndarray:
    """(n, 2, 3) two unit axes spanning the plane normal to each of `normals` (n, 3): the
    first is world x laid onto that plane (world y where x is nearly the normal)."""
    x = np.zeros((len(normals), 3))
    steep = np.abs(normals[:, 0]) > 0.9
    x[:, 0] = ~steep
    x[:, 1] = steep
    first = x - np.sum(x * normals, axis=1, keepdims=True) * normals
    first /= np.linalg.norm(first, axis=1, keepdims=True)
    basis = np.empty((len(normals), 2, 3))
    basis[:, 0] = first
    basis[:, 1] = cross(normals, first)
    return basis


def _in_plane(basis: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """(n, 2) coordinates of `vectors` (n, 3) along each row's plane axes (n, 2, 3)."""
    coordinates: np.ndarray = np.einsum("nij,nj->ni", basis, vectors)
    return coordinates


class TentacleSelection(System):
    name = "tentacle_selection"
    stage = "decide"
    after = ("goals",)
    sets = (DESTINATIONS_READ,)
    reads = (
        "transforms.pos",
        "tentacles.creature_row",
        "tentacles.base_row",
        "tentacles.joint_limit",
        "creatures.mantle_row",
        "creatures.first_tentacle",
        "creatures.tentacles",
        "locomotion.creatures",
        "locomotion.tentacles.action",
        "locomotion.tentacles.speed",
        "locomotion.tentacles.target_angle",
        "creatures.mantle_radius",
        "tentacles.length",
    )
    writes = (
        "locomotion.creatures.steer",
        "locomotion.tentacles.driving",
        "locomotion.tentacles.mode",
        "locomotion.tentacles.started",
        "locomotion.tentacles.interrupted",
        "locomotion.creatures.next_driver",
        "locomotion.creatures.last_start",
        "action_queues",
    )

    def setup(self, world: Host) -> None:
        gait = parameter("locomotion", "gait")  # stored codes: the schema's choices' indices
        self.cyclic, self.coordinated = gait.code("cyclic"), gait.code("coordinated")
        self.queues = ActionQueues(world)
        loco = world.resource(LocomotionStores)
        self.strokes, self.gaits = loco.tentacles, loco.creatures

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self.queues.roster_changed(world, change)  # the queues by tentacle row

    def process(self, world: Host, dt: float) -> None:
        t, c = world.tentacles, world.creatures
        s, g = self.strokes, self.gaits
        world.resource(Navigator).steer(world)  # the goal, or a waypoint on the way to it
        if not len(t) or not (g.has_goal.any() or s.driving.any()):
            return
        creature = t.creature_row
        replayed = world.physics.kinematic_creatures(len(c))  # their strokes drive nothing
        live = np.flatnonzero(~replayed[creature])  # tentacle rows worth classifying
        to_goal, to_base, pull, cos = self._classified(world, live, ~replayed & g.has_goal)
        for row in self._aborts(creature, cos, replayed):
            self._abort(world, int(row))
        first, ready = self._starts(world.time, creature, replayed)
        for row in first:  # cyclic gaits: the next tentacle in turn
            k = int(c.first_tentacle[row] + g.next_driver[row])
            self._start(world, k, Mode.PULL if pull[k] else Mode.PUSH, orient=None)
            g.next_driver[row] = (g.next_driver[row] + 1) % c.tentacles[row]
        for row in ready:  # the others: the best placed free tentacle
            self._start_best(world, int(row), cos, pull, to_goal, to_base)

    def _aborts(self, creature: np.ndarray, cos: np.ndarray, replayed: np.ndarray) -> np.ndarray:
        """Tentacle rows whose stroke stops: their creature lost its goal, or (coordinated
        gaits) the goal is now well on the wrong side of the stroke."""
        s, g = self.strokes, self.gaits
        fast = KERNELS.get()
        if fast is not None:  # the same rows in one pass
            return np.asarray(fast.aborts(creature, g.has_goal, s.driving, g.gait,
                                          self.coordinated, s.mode, PULL, cos, ABORT_MARGIN,
                                          replayed))  # fmt: skip
        if not s.driving.any():
            return np.zeros(0, dtype=np.int64)
        wrong_side = (g.gait[creature] == self.coordinated) & np.where(
            s.mode == PULL, cos < -ABORT_MARGIN, cos > ABORT_MARGIN
        )
        abort = s.driving & (~g.has_goal[creature] | wrong_side) & ~replayed[creature]
        return np.flatnonzero(abort)

    def _starts(
        self, now: float, creature: np.ndarray, replayed: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(cyclic, ready) creature rows that start a stroke now: with a goal, simulated,
        fewer tentacles driving than their drivers; cyclic ones with none driving, the
        others a stagger after their last start."""
        s, g = self.strokes, self.gaits
        fast = KERNELS.get()
        if fast is not None:  # the same rows in one pass
            first, ready = fast.starts(creature, s.driving, g.has_goal, g.drivers, replayed,
                                       g.gait, self.cyclic, g.speed, g.last_start, now,
                                       STROKE_SECONDS)  # fmt: skip
            return np.asarray(first), np.asarray(ready)
        driving = np.bincount(creature, weights=s.driving, minlength=len(g.has_goal))
        idle_goal = g.has_goal & (driving < g.drivers) & ~replayed
        if not idle_goal.any():
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        cyclic = g.gait == self.cyclic
        stagger = STROKE_SECONDS / (g.speed * g.drivers)
        ready = idle_goal & ~cyclic & (now - g.last_start >= stagger)
        return np.flatnonzero(idle_goal & cyclic & (driving == 0)), np.flatnonzero(ready)

    def _classified(
        self, world: Host, live: np.ndarray, driven: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(to_goal, to_base, pull, cos) per tentacle row, filled at rows `live` (`_vectors`
        and `classify`; on the plane by one kernel when numba is installed)."""
        t = world.tentacles
        pull, cos = np.zeros(len(t), dtype=bool), np.zeros(len(t))
        fast = KERNELS.get()
        if fast is not None and len(live) and ground_of(world).flat:
            to_goal, to_base = np.zeros((len(t), 2)), np.zeros((len(t), 2))
            g = self.gaits
            fast.flat_vectors(world.transforms.pos, world.creatures.mantle_row, g.steer,
                              g.avoidance, t.base_row, t.creature_row, live, PULL_TOLERANCE,
                              to_goal, to_base, pull, cos)  # fmt: skip
            return to_goal, to_base, pull, cos
        to_goal, to_base = self._vectors(world, live, driven)
        pull[live], cos[live] = classify(to_goal[live], to_base[live])
        return to_goal, to_base, pull, cos

    def _vectors(
        self, world: Host, live: np.ndarray, driven: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(tentacles, 2) ground-plane vectors mantle -> goal (turned by avoidance) and
        mantle -> base, filled at tentacle rows `live` (zero elsewhere); on terrain the
        plane is the one under each mantle of the `driven` creatures (world xy else)."""
        t, c, g = world.tentacles, world.creatures, self.gaits
        to_goal, to_base = np.zeros((len(t), 2)), np.zeros((len(t), 2))
        if not len(live):
            return to_goal, to_base
        creature = t.creature_row[live]
        pos = world.transforms.pos
        ground = ground_of(world)
        if ground.flat:
            mantle = pos[c.mantle_row, :2]
            to_goal[live] = bent(g.steer[:, :2] - mantle, g.avoidance)[creature]
            to_base[live] = pos[t.base_row[live], :2] - mantle[creature]
            return to_goal, to_base
        mantle3 = pos[c.mantle_row]
        normals = np.zeros((len(c), 3))
        normals[:, 2] = 1.0
        normals[driven] = ground.normal_under(mantle3[driven, :2])
        basis = ground_plane(normals)[creature]  # (n, 2, 3)
        to_goal[live] = _in_plane(basis, bent(g.steer - mantle3, g.avoidance)[creature])
        to_base[live] = _in_plane(basis, pos[t.base_row[live]] - mantle3[creature])
        return to_goal, to_base

    def _start_best(
        self,
        world: Host,
        creature_row: int,
        cos: np.ndarray,
        pull: np.ndarray,
        to_goal: np.ndarray,
        to_base: np.ndarray,
    ) -> None:
        t, c, s = world.tentacles, world.creatures, self.strokes
        first = int(c.first_tentacle[creature_row])
        rows = np.arange(first, first + int(c.tentacles[creature_row]))
        free = ~s.driving[rows] & (s.action[rows] == Kind.IDLE)
        score = np.abs(cos[rows]) * np.where(pull[rows], 1.0, PUSH_PREFERENCE)
        score[~free] = -1.0
        best = int(np.argmax(score))
        if score[best] < MIN_SCORE:
            return
        k = int(rows[best])
        mode = Mode.PULL if pull[k] else Mode.PUSH
        wanted = to_goal[k] if mode == Mode.PULL else -to_goal[k]
        base = to_base[k]
        turn = np.arctan2(base[0] * wanted[1] - base[1] * wanted[0], base @ wanted)
        limit = 1.8 * t.joint_limit[k]  # the sweep is shared by the first two joints
        self._start(world, k, mode, orient=float(np.clip(turn, -limit, limit)))
        self.gaits.last_start[creature_row] = world.time

    def _speed(self, world: Host, row: int) -> float:
        """Tentacle `row`'s pace: its own speed times its creature's."""
        creature = world.tentacles.creature_row[row]
        return float(self.strokes.speed[row] * self.gaits.speed[creature])

    def _start(self, world: Host, row: int, mode: Mode, orient: float | None) -> None:
        s = self.strokes
        speed = self._speed(world, row)
        # queued after whatever is pending; the current action ends now
        self.queues[row].extend(drive_sequence(mode, float(s.target_angle[row]), speed, orient))
        self.queues.interrupt(row)
        s.driving[row] = True
        s.mode[row] = mode
        s.started[row] = world.time

    def _abort(self, world: Host, row: int) -> None:
        s = self.strokes
        speed = self._speed(world, row)
        self.queues.replace(row, [action(Kind.DETACH, speed), action(Kind.SETTLE, speed)])
        s.driving[row] = False
        s.mode[row] = Mode.NONE
