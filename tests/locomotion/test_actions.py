"""Actions and the push and pull sequences (thesis IV.B)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.locomotion.actions import (
    BASE_SECONDS,
    GRIPPING,
    STRENGTH,
    Action,
    ActionQueue,
    ActionQueues,
    Kind,
    Mode,
    drive_sequence,
    make_action,
)
from ecs_tentacles.world import World
from tests.conftest import crawlers, creature_scene

PUSH = [Kind.COMPRESS, Kind.ATTACH, Kind.PUSH, Kind.DETACH]
PULL = [Kind.EXTEND, Kind.ATTACH, Kind.PULL, Kind.DETACH]


@pytest.mark.parametrize("speed", [1.0, 2.0])
@pytest.mark.parametrize(
    ("mode", "kinds"), [(Mode.PUSH, PUSH), (Mode.PULL, PULL)], ids=["push", "pull"]
)
def test_drive_sequences(mode: Mode, kinds: list[Kind], speed: float) -> None:
    actions = drive_sequence(mode, 0.7, speed)
    assert [a.kind for a in actions] == kinds
    assert [a.duration for a in actions] == [BASE_SECONDS[k] / speed for k in kinds]
    assert [a.angle for a in actions] == [0.7] * 4
    assert [a.strength for a in actions] == [STRENGTH[k] for k in kinds]


def test_power_strokes_are_at_full_strength() -> None:
    pull = drive_sequence(Mode.PULL, 0.7, 1.0)
    assert [a.strength for a in pull] == [0.8, 1.0, 1.0, 0.8]


@pytest.mark.parametrize(
    ("mode", "kinds"), [(Mode.PUSH, PUSH), (Mode.PULL, PULL)], ids=["push", "pull"]
)
def test_oriented_sequence_aims_first_and_settles_after(mode: Mode, kinds: list[Kind]) -> None:
    actions = drive_sequence(mode, 0.7, 2.0, orient=-0.4)
    assert [a.kind for a in actions] == [Kind.ORIENT, *kinds, Kind.SETTLE]
    assert actions[0] == Action(Kind.ORIENT, BASE_SECONDS[Kind.ORIENT] / 2.0, -0.4, 0.8)
    assert actions[-1] == Action(Kind.SETTLE, BASE_SECONDS[Kind.SETTLE] / 2.0, 0.0, 0.6)
    assert [a.angle for a in actions[1:-1]] == [0.7] * 4
    assert [a.duration for a in actions] == [
        BASE_SECONDS[k] / 2.0 for k in [Kind.ORIENT, *kinds, Kind.SETTLE]
    ]


def test_orient_of_zero_still_aims() -> None:
    actions = drive_sequence(Mode.PULL, 0.7, 1.0, orient=0.0)
    assert [a.kind for a in actions] == [Kind.ORIENT, *PULL, Kind.SETTLE]
    assert actions[0].angle == 0.0


def test_make_action() -> None:
    assert make_action(Kind.PUSH, 4.0, 0.3) == Action(Kind.PUSH, 0.55 / 4.0, 0.3, 1.0)
    assert make_action(Kind.SETTLE, 0.5) == Action(Kind.SETTLE, 0.3, 0.0, 0.6)


@pytest.mark.parametrize("speed", [0.0, -1.0])
def test_make_action_needs_a_positive_speed(speed: float) -> None:
    with pytest.raises(ValueError, match=r"^speed must be > 0, got "):
        make_action(Kind.EXTEND, speed)
    with pytest.raises(ValueError, match=r"^speed must be > 0, got "):
        drive_sequence(Mode.PULL, 0.5, speed)


def test_a_drive_is_a_push_or_a_pull() -> None:
    with pytest.raises(ValueError, match=r"^a drive is a push or a pull, got <Mode.NONE: 0>$"):
        drive_sequence(Mode.NONE, 0.5, 1.0)
    with pytest.raises(ValueError, match="a drive is a push or a pull"):
        drive_sequence(Mode.NONE, 0.5, 1.0, orient=0.2)


def test_action_queue_names_its_pending_actions() -> None:
    queue = ActionQueue()
    assert queue.kinds() == []
    queue.extend(drive_sequence(Mode.PUSH, 0.5, 1.0, orient=0.1))
    assert queue.kinds() == ["orient", "compress", "attach", "push", "detach", "settle"]
    assert len(queue) == 6
    queue.clear()
    assert (len(queue), queue.kinds()) == (0, [])


def test_a_queue_never_used_holds_no_deque_and_a_used_one_keeps_its_own() -> None:
    queue = ActionQueue()
    assert len(queue) == 0 and queue.kinds() == [] and not queue
    queue.clear()
    with pytest.raises(IndexError):
        queue.popleft()
    assert queue.__dict__["_pending"] is None  # an empty deque is 760 bytes a tentacle
    pending = queue.pending
    queue.extend(drive_sequence(Mode.PUSH, 0.5, 1.0))
    assert queue.pending is pending and len(pending) == 4
    assert queue.popleft().kind == Kind.COMPRESS and queue.kinds() == ["attach", "push", "detach"]


def test_a_crowd_of_replayed_creatures_makes_no_deques(make_world: Callable[..., World]) -> None:
    scene = crawlers(3) | {"physics": {"lod": {"full": 0, "reduced": 0}}}  # goals to crawl to
    world = make_world(scene)
    world.step(30)  # replayed from the first frame on: one stroke queued then, no more
    assert world.lod.counts()["kinematic"] == 3
    made = [q.__dict__["_pending"] is not None for _, q in world.query(ActionQueue)]
    assert len(made) == 9 and sum(made) <= 3  # a deque only where a stroke was queued


def test_gripping_actions_are_attach_push_and_pull() -> None:
    assert [k for k in Kind if GRIPPING[k]] == [Kind.ATTACH, Kind.PUSH, Kind.PULL]


def test_action_queues_reach_every_tentacle_queue_by_row(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=3, links=2)
    scene["creatures"].append({**scene["creatures"][0], "name": "other", "position": [2, 0]})
    world = make_world(scene)
    queues = ActionQueues(world)
    assert len(queues) == 6
    for name in ("octo", "other"):
        for entity in world.component(world.creature(name), Creature).tentacles:
            row = world.component(entity, Tentacle).row
            assert queues[row] is world.component(entity, ActionQueue)


def test_replace_empties_the_queue_and_marks_the_tentacle(
    make_world: Callable[..., World],
) -> None:
    world = make_world(creature_scene(count=3, links=2))
    queues = ActionQueues(world)
    queues[1].extend(drive_sequence(Mode.PUSH, 0.5, 1.0))
    queues.replace(1, [make_action(Kind.DETACH, 1.0)])
    assert queues[1].kinds() == ["detach"]
    assert world.stores["locomotion.tentacles"].interrupted.tolist() == [False, True, False]
    queues[2].extend([make_action(Kind.SETTLE, 1.0)])
    queues.interrupt(2)  # keeps what is pending
    assert queues[2].kinds() == ["settle"]
    assert world.stores["locomotion.tentacles"].interrupted.tolist() == [False, True, True]
