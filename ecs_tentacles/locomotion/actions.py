"""Actions a tentacle performs, and the push and pull sequences of the thesis (IV.B).

Push = compress -> attach -> push (extend while attached) -> detach.
Pull = extend -> attach -> pull (compress while attached) -> detach.
The coordinated gait orients the tentacle toward the goal line first and settles
after. Durations are base seconds divided by the creature's and tentacle's speed.

Each tentacle's pending actions are its `ActionQueue` component; the current action
lives in its `TentacleStore` row. `ActionQueues` reaches every queue by row and is how
a system or script cuts the current action short (`interrupt`, `replace`).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from enum import IntEnum
from typing import TYPE_CHECKING, overload

import numpy as np

from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.locomotion.stores import LocomotionStores

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange


class Kind(IntEnum):
    """What a tentacle is doing; the value is stored in `TentacleStore.action`."""

    IDLE = 0  # writhe in place
    COMPRESS = 1  # arch up, shortening the tentacle
    EXTEND = 2  # straighten, tip lifted
    ORIENT = 3  # sweep the base toward the goal line
    ATTACH = 4  # press the tip down; the sucker grabs when it touches
    DETACH = 5  # let go, lift the tip
    PUSH = 6  # extend while attached
    PULL = 7  # compress while attached
    SETTLE = 8  # relax to the rest pose


class Mode(IntEnum):
    """Why a tentacle is driving."""

    NONE = 0
    PUSH = 1
    PULL = 2


BASE_SECONDS: dict[Kind, float] = {
    Kind.COMPRESS: 0.35,
    Kind.EXTEND: 0.25,
    Kind.ORIENT: 0.2,
    Kind.ATTACH: 0.15,
    Kind.DETACH: 0.1,
    Kind.PUSH: 0.55,
    Kind.PULL: 0.55,
    Kind.SETTLE: 0.15,
}

# Relative motor strength during each action: power strokes at full strength.
STRENGTH: dict[Kind, float] = {
    Kind.IDLE: 0.6,
    Kind.COMPRESS: 0.8,
    Kind.EXTEND: 0.8,
    Kind.ORIENT: 0.8,
    Kind.ATTACH: 1.0,
    Kind.DETACH: 0.8,
    Kind.PUSH: 1.0,
    Kind.PULL: 1.0,
    Kind.SETTLE: 0.6,
}

# An attach action waits for its sucker to grip, up to this many times its duration.
ATTACH_PATIENCE = 3.0

# Actions during which the tip sucker holds the ground (attach: reaches for it); any
# other action lets go. Indexed by Kind.
GRIPPING = np.zeros(len(Kind), dtype=bool)
GRIPPING[[Kind.ATTACH, Kind.PUSH, Kind.PULL]] = True


@dataclass(frozen=True)
class Action:
    """One queued action: `kind`, how long (`duration` s), `angle` (rad), `strength`."""

    kind: Kind
    duration: float
    angle: float = 0.0
    strength: float = 1.0


def make_action(kind: Kind, speed: float, angle: float = 0.0) -> Action:
    """An action of `kind` with its base duration divided by `speed`."""
    if speed <= 0:
        raise ValueError(f"speed must be > 0, got {speed}")
    return Action(kind, BASE_SECONDS[kind] / speed, angle, STRENGTH[kind])


def drive_sequence(
    mode: Mode, angle: float, speed: float, orient: float | None = None
) -> list[Action]:
    """The actions of one push or pull stroke; with `orient`, aim first and settle after."""
    if mode == Mode.PUSH:
        kinds = [Kind.COMPRESS, Kind.ATTACH, Kind.PUSH, Kind.DETACH]
    elif mode == Mode.PULL:
        kinds = [Kind.EXTEND, Kind.ATTACH, Kind.PULL, Kind.DETACH]
    else:
        raise ValueError(f"a drive is a push or a pull, got {mode!r}")
    actions = [make_action(kind, speed, angle) for kind in kinds]
    if orient is not None:
        actions = [
            make_action(Kind.ORIENT, speed, orient),
            *actions,
            make_action(Kind.SETTLE, speed),
        ]
    return actions


class _Pending:
    """`ActionQueue.pending`: a deque made on first use. An empty deque is 760 bytes, and
    most of a crowd's 80,000 tentacles never queue an action (replayed creatures' clips
    carry theirs): until one is asked for, the queue holds None."""

    @overload
    def __get__(self, queue: None, owner: type) -> None: ...
    @overload
    def __get__(self, queue: ActionQueue, owner: type) -> deque[Action]: ...
    def __get__(self, queue: ActionQueue | None, owner: type) -> deque[Action] | None:
        if queue is None:  # the dataclass's default (none given): made on first use
            return None
        made: deque[Action] | None = queue.__dict__.get("_pending")
        if made is None:
            made = queue.__dict__["_pending"] = deque()
        return made

    def __set__(self, queue: ActionQueue, actions: deque[Action] | None) -> None:
        queue.__dict__["_pending"] = actions


@dataclass(eq=False)
class ActionQueue:
    """A tentacle's pending actions (the current one lives in the TentacleStore row).

    `pending` is a deque of them; the methods below reach it without making one for a
    queue that never held an action (`_Pending`)."""

    pending: _Pending = _Pending()

    def _made(self) -> deque[Action] | None:
        made: deque[Action] | None = self.__dict__.get("_pending")
        return made

    def extend(self, actions: Iterable[Action]) -> None:
        self.pending.extend(actions)

    def clear(self) -> None:
        made = self._made()
        if made is not None:
            made.clear()

    def popleft(self) -> Action:
        """The next pending action, taken off the queue (IndexError when there is none)."""
        made = self._made()
        if made is None:
            raise IndexError("pop from an empty action queue")
        return made.popleft()

    def __len__(self) -> int:
        made = self._made()
        return 0 if made is None else len(made)

    def kinds(self) -> list[str]:
        """Names of the pending actions, for the HUD and tests."""
        return [action.kind.name.lower() for action in self._made() or ()]


class ActionQueues:
    """Every tentacle's `ActionQueue` by TentacleStore row, and how to cut one short.

        queues = ActionQueues(world)
        queues.replace(row, [make_action(Kind.DETACH, 1.0)])  # drop all, detach now

    `interrupt(row)` ends tentacle `row`'s current action: the action_queue system starts
    its next pending action (or idles it) this frame, or next frame if it already ran.
    The mark is the store's `interrupted` column, so every `ActionQueues` of a world
    shares it. Built from the tentacles the world has now.
    """

    def __init__(self, world: Host):
        self._tentacles = world.resource(LocomotionStores).tentacles
        by_row = {t.row: world.component(e, ActionQueue) for e, t in world.query(Tentacle)}
        # a row without a tentacle entity (stores filled by hand) gets a queue of its own
        self._queues = [
            by_row[row] if row in by_row else ActionQueue() for row in range(len(world.tentacles))
        ]

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """Follow a spawn (its tentacles' queues appended) or a despawn (its dropped)."""
        if not change.spawned:
            kept = np.flatnonzero(change.moved["tentacles"] >= 0).tolist()
            self._queues = [self._queues[i] for i in kept]
            return
        creature = world.component(change.creature, Creature)
        self._queues += [world.component(t, ActionQueue) for t in creature.tentacles]

    def __getitem__(self, row: int) -> ActionQueue:
        return self._queues[row]

    def __len__(self) -> int:
        return len(self._queues)

    def interrupt(self, row: int) -> None:
        """End tentacle `row`'s current action now; its pending actions stay queued."""
        self._tentacles.interrupted[row] = True

    def replace(self, row: int, actions: Iterable[Action]) -> None:
        """Drop tentacle `row`'s current and pending actions; `actions` start now."""
        queue = self._queues[row]
        queue.clear()
        queue.extend(actions)
        self.interrupt(row)
