"""World snapshots: restore continues bit-identically; worlds close themselves."""

from __future__ import annotations

from collections.abc import Callable

import esper
import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.world import World


def _state(world: World) -> list[np.ndarray]:
    groups = world.physics.views
    physics = [a for g in groups for a in (g.data.qpos, g.data.qvel, g.integration_state())]
    stores = [
        world.transforms.pos,
        world.motors.target,
        world.suckers.anchor,
        world.resource(FurData).curves,
    ]
    return [
        np.array(a, copy=True)
        for a in (*physics, *stores, world.stores["locomotion.tentacles"].timer)
    ]


def test_restore_continues_bit_identically_with_suckers_attached(
    make_world: Callable[..., World],
) -> None:
    world = make_world("hedgehog_octopus")  # fur with dynamics
    octo = int(world.creatures.entity[0])
    world.resource(GoalBook).set(octo, [1.5, 0.0])  # crawl, with suckers
    for _ in range(600):
        if world.suckers.attached.any():
            break
        world.step(1)
    assert world.suckers.attached.any()
    snap = world.snapshot()
    actions = world.resource(Locomotion).actions(octo)
    world.step(300)
    first = _state(world)
    reached = world.events.counts["goal_reached"]
    world.restore(snap)
    assert world.suckers.attached.any() and world.frame == snap.frame
    assert world.resource(Locomotion).actions(octo) == actions
    world.step(300)
    for a, b in zip(first, _state(world), strict=True):
        assert_array_equal(a, b)
    assert world.events.counts["goal_reached"] == 2 * reached  # the same goals again


def test_world_is_a_context_manager() -> None:
    with World.from_scene("octopus") as world:
        context = world.context
        world.step(2)
    assert context not in esper.list_worlds()


def test_a_snapshot_of_another_world_is_refused_and_changes_nothing(
    make_world: Callable[..., World],
) -> None:
    import pytest

    from ecs_tentacles.snapshot import SnapshotMismatch

    def small(count: int) -> dict[str, object]:
        creatures = [{"name": f"c{i}", "position": [3.0 * i, 0.0]} for i in range(count)]
        return {"version": 1, "creatures": creatures}

    world, twin, other = make_world(small(1)), make_world(small(1)), make_world(small(2))
    for w in (world, twin):
        w.step(7)
    other.step(5)
    bodies = len(world.transforms)
    with pytest.raises(SnapshotMismatch, match="cannot restore a snapshot of another world: "):
        world.restore(other.snapshot())
    assert world.frame == 7 and len(world.transforms) == bodies
    for w in (world, twin):
        w.step(10)
    for mine, theirs in zip(_state(world), _state(twin), strict=True):
        assert_array_equal(mine, theirs)  # as if the restore had never been asked for


def test_a_handler_that_spawns_during_a_restore_runs_after_it_whole() -> None:
    """A `creature_despawned` handler spawning while a restore despawned the newcomers left
    the world half-restored (roster altered, frame and state not), then SnapshotMismatch."""
    from ecs_tentacles.components import Creature

    def octo(name: str, x: float) -> dict:
        return {"name": name, "position": [x, 0.0], "tentacles": {"count": 4, "links": 3}}

    scene = {"version": 1, "creatures": [octo("a", 0.0), octo("b", 5.0)]}
    with World.from_scene(scene) as world, World.from_scene(scene) as twin:
        world.step(5)
        twin.step(5)
        snap = world.snapshot()
        world.spawn(octo("c", 10.0))
        world.step(7)
        seen: list[tuple[str, int]] = []

        def replace(**event: object) -> None:
            seen.append((str(event["creature_name"]), world.frame))
            world.spawn(octo("d", -10.0))  # as a script that keeps a crowd at full strength

        world.events.on("creature_despawned", replace)
        world.restore(snap)
        assert seen == [("c", 5)]  # after the restore: at the snapshot's frame
        assert world.frame == 5
        assert sorted(c.name for _, c in world.query(Creature)) == ["a", "b", "d"]
        world.step(20)
        twin.step(20)
        for name in ("a", "b"):  # restored exactly: as if c had never come
            mine = world.physics.view_of(world.component(world.creature(name), Creature))
            theirs = twin.physics.view_of(twin.component(twin.creature(name), Creature))
            assert_array_equal(
                world.transforms.pos[mine.body_rows], twin.transforms.pos[theirs.body_rows]
            )
