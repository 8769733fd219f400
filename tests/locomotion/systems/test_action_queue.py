"""action_queue: timers, one action after another, attach waits for the sucker."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.locomotion.actions import (
    ATTACH_PATIENCE,
    BASE_SECONDS,
    STRENGTH,
    ActionQueues,
    Kind,
    Mode,
    drive_sequence,
    make_action,
)
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.world import World
from tests.conftest import ByBackend, creature_scene


def _frames(seconds: float, fps: float) -> int:
    """Whole frames an action of `seconds` lasts: its duration rounded up."""
    return math.ceil(round(seconds * fps, 9))


def _runs(actions: list[int]) -> list[tuple[str, int]]:
    return [(Kind(kind).name.lower(), len(list(run))) for kind, run in itertools.groupby(actions)]


@pytest.mark.parametrize("speed", [1.0, 2.0])
def test_pull_sequence_runs_each_action_for_its_duration(
    make_world: Callable[..., World], speed: float
) -> None:
    # no goal: nothing but the queue we fill changes tentacle 0's action
    world = make_world(creature_scene(count=2, links=10))
    octo = world.creature("octo")
    fps = world.settings.fps
    t = world.stores["locomotion.tentacles"]
    tip = int(world.tentacles.tip_sucker[0])
    world.step(5)
    assert world.resource(Locomotion).queue(octo, 0) == ["idle"]
    sequence = drive_sequence(Mode.PULL, float(t.target_angle[0]), speed)
    ActionQueues(world).replace(0, sequence)  # the idle action ends: extend starts this frame
    actions: list[int] = []
    attached: list[bool] = []
    for _ in range(100):
        world.step(1)
        actions.append(int(t.action[0]))
        attached.append(bool(world.suckers.attached[tip]))
    runs = _runs(actions)
    assert [name for name, _ in runs] == ["extend", "attach", "pull", "detach", "idle"]
    # the attach action ends on the frame after its sucker grips, but never early
    start = runs[0][1]
    gripped = attached.index(True) - start + 1
    attach = sequence[1].duration
    attach_frames = max(_frames(attach, fps), gripped)
    assert attach_frames <= _frames(ATTACH_PATIENCE * attach, fps)
    assert runs[:4] == [
        ("extend", _frames(sequence[0].duration, fps)),
        ("attach", attach_frames),
        ("pull", _frames(sequence[2].duration, fps)),
        ("detach", _frames(sequence[3].duration, fps)),
    ]


def test_every_action_lasts_its_duration_rounded_up_to_whole_frames(
    make_world: Callable[..., World],
) -> None:
    # one tentacle per action kind (attach waits for its sucker: tested on its own)
    kinds = [kind for kind in BASE_SECONDS if kind != Kind.ATTACH]
    world = make_world(creature_scene(count=len(kinds), links=2))
    t = world.stores["locomotion.tentacles"]
    queues = ActionQueues(world)
    for row, kind in enumerate(kinds):
        queues.replace(row, [make_action(kind, 1.0)])
    actions = []
    for _ in range(40):
        world.step(1)
        actions.append(t.action.copy())
    lasted = {
        kind.name.lower(): _runs(list(np.array(actions)[:, row]))[0][1]
        for row, kind in enumerate(kinds)
    }
    fps = world.settings.fps
    assert lasted == {kind.name.lower(): _frames(BASE_SECONDS[kind], fps) for kind in kinds}


def test_attach_gives_up_after_three_times_its_duration(make_world: Callable[..., World]) -> None:
    # weightless and lifted: the tip never reaches the ground, the sucker never grips
    scene = creature_scene(count=2, links=6)
    scene["physics"] = {"gravity": [0, 0, 0]}
    scene["creatures"][0]["position"] = [0, 0, 0.5]
    world = make_world(scene)
    t = world.stores["locomotion.tentacles"]
    ActionQueues(world).replace(0, drive_sequence(Mode.PUSH, 0.5, 1.0))
    actions = []
    for _ in range(90):
        world.step(1)
        actions.append(int(t.action[0]))
    assert world.events.counts["sucker_attached"] == 0
    fps = world.settings.fps
    assert _runs(actions)[:3] == [
        ("compress", _frames(0.35, fps)),
        ("attach", _frames(ATTACH_PATIENCE * 0.15, fps)),
        ("push", _frames(0.55, fps)),
    ]


def test_empty_queue_idles_for_ever(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=3))
    octo = world.creature("octo")
    t = world.stores["locomotion.tentacles"]
    ActionQueues(world).replace(1, drive_sequence(Mode.PUSH, 0.5, 5.0)[-1:])  # one detach, 0.02 s
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 1) == ["detach"]
    assert t.duration[1] == 0.1 / 5.0
    assert t.action_strength[1] == STRENGTH[Kind.DETACH]
    world.step(2)
    assert world.resource(Locomotion).queue(octo, 1) == ["idle"]
    assert t.action[1] == Kind.IDLE
    assert t.duration[1] == np.inf
    assert t.action_strength[1] == STRENGTH[Kind.IDLE]
    assert t.action_angle[1] == 0.0
    assert t.orient[1] == 0.0
    assert t.mode[1] == Mode.NONE
    assert not t.driving[1]
    world.step(60)
    assert world.resource(Locomotion).actions(octo) == ["idle", "idle"]


def test_orient_angle_is_held_until_settle(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=2, links=3))
    t = world.stores["locomotion.tentacles"]
    ActionQueues(world).replace(0, drive_sequence(Mode.PUSH, 0.5, 10.0, orient=0.3))
    orient = []
    actions = []
    for _ in range(40):
        world.step(1)
        orient.append(float(t.orient[0]))
        actions.append(int(t.action[0]))
    settle = actions.index(Kind.SETTLE)
    assert actions[0] == Kind.ORIENT
    assert orient[:settle] == [0.3] * settle
    assert orient[settle:] == [0.0] * (40 - settle)


# -- interrupting (ActionQueues) --------------------------------------------------------

TEN_SECONDS = 0.35 / 10.0  # the speed that makes a compress last 10 s


def _busy(make_world: Callable[..., World]) -> World:
    """A two-tentacle world whose tentacle 0 is 5 frames into a 10 s compress."""
    world = make_world(creature_scene(count=2, links=3))
    ActionQueues(world).replace(0, [make_action(Kind.COMPRESS, TEN_SECONDS)])
    world.step(5)
    assert world.resource(Locomotion).queue(world.creature("octo"), 0) == ["compress"]
    return world


def test_replace_starts_the_new_actions_the_same_frame(make_world: Callable[..., World]) -> None:
    world = _busy(make_world)
    octo = world.creature("octo")
    t = world.stores["locomotion.tentacles"]
    idle_timer = float(t.timer[1])
    sequence = drive_sequence(Mode.PULL, 0.5, 1.0)
    ActionQueues(world).replace(0, sequence)
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["extend", "attach", "pull", "detach"]
    assert (t.timer[0], t.duration[0]) == (0.0, sequence[0].duration)
    assert not t.interrupted.any()
    # the other tentacle goes on as before
    assert world.resource(Locomotion).queue(octo, 1) == ["idle"]
    assert t.timer[1] == idle_timer + world.settings.dt
    # the new action is not cut short in turn: it lasts its whole duration
    actions = []
    for _ in range(30):
        world.step(1)
        actions.append(int(t.action[0]))
    extend = 1 + actions.index(Kind.ATTACH)
    assert extend == _frames(sequence[0].duration, world.settings.fps)


def test_interrupt_ends_the_current_action_and_keeps_the_pending_ones(
    make_world: Callable[..., World],
) -> None:
    world = _busy(make_world)
    octo = world.creature("octo")
    queues = ActionQueues(world)
    queues[0].extend([make_action(Kind.DETACH, 1.0), make_action(Kind.SETTLE, 1.0)])
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["compress", "detach", "settle"]
    queues.interrupt(0)
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["detach", "settle"]
    queues.interrupt(0)
    queues.interrupt(0)  # twice in a frame is once
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["settle"]


def test_interrupt_with_nothing_pending_idles_at_once(make_world: Callable[..., World]) -> None:
    world = _busy(make_world)
    t = world.stores["locomotion.tentacles"]
    ActionQueues(world).interrupt(0)
    world.step(1)
    assert world.resource(Locomotion).queue(world.creature("octo"), 0) == ["idle"]
    assert (t.duration[0], t.action_strength[0]) == (np.inf, STRENGTH[Kind.IDLE])


def test_interrupt_ends_an_attach_that_waits_for_its_sucker(
    make_world: Callable[..., World],
) -> None:
    # weightless and lifted: the sucker never grips, so the attach would wait 3x its 1.5 s
    scene = creature_scene(count=2, links=6)
    scene["physics"] = {"gravity": [0, 0, 0]}
    scene["creatures"][0]["position"] = [0, 0, 0.5]
    world = make_world(scene)
    octo = world.creature("octo")
    queues = ActionQueues(world)
    queues.replace(0, [make_action(Kind.ATTACH, 0.1), make_action(Kind.PUSH, 1.0)])
    world.step(20)
    assert world.resource(Locomotion).queue(octo, 0) == ["attach", "push"]
    queues.interrupt(0)
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["push"]
    assert world.events.counts["sucker_attached"] == 0


def test_the_kernel_advances_the_same_actions_as_numpy_bit_for_bit(
    worlds_by_backend: ByBackend,
) -> None:
    """A crowd crawling, some of it replayed (its actions pause): the same timers,
    actions and poses with numba's one pass and with numpy's whole-array steps."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.locomotion.stores import LocomotionStores
    from ecs_tentacles.locomotion.systems.action_queue import KERNELS
    from ecs_tentacles.physics.tiers import KINEMATIC

    assert KERNELS.get() is not None  # numba comes with the dev extra
    scene = crowd_scene(6, seed=2, uniform=True)  # one body plan, the replay tests' (one clip)
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2}
    kernel, numpy_path = worlds_by_backend(KERNELS, scene, 30)
    assert (kernel.physics.roster.tier == KINEMATIC).sum() >= 3  # some actions paused
    for name in ("timer", "duration", "action", "interrupted", "driving", "mode"):
        np.testing.assert_array_equal(
            getattr(kernel.resource(LocomotionStores).tentacles, name),
            getattr(numpy_path.resource(LocomotionStores).tentacles, name),
        )
    assert (kernel.resource(LocomotionStores).tentacles.action != Kind.IDLE).any()
    np.testing.assert_array_equal(kernel.transforms.pos, numpy_path.transforms.pos)
