"""Spawning and despawning creatures in a running world (real MuJoCo throughout)."""

from __future__ import annotations

import copy
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Motor, Tentacle, Transform
from ecs_tentacles.creatures.spawning import SpawnError
from ecs_tentacles.world import World
from tests.creatures.spawn_scenes import APART, creature_entry, scene_of


def _bodies(world: World, name: str) -> np.ndarray:
    """Every body pose of creature `name` (mantle then links), as one array."""
    creature = world.component(world.creature(name), Creature)
    view = world.physics.view_of(creature)
    rows = view.body_rows
    return np.concatenate([world.transforms.pos[rows], world.transforms.quat[rows]], axis=1)


@contextmanager
def _twins() -> Iterator[tuple[World, World]]:
    """Two identical worlds of `APART`, 20 frames in, stepped on two threads."""
    with World.from_scene(scene_of(APART), threads=2) as one:
        with World.from_scene(scene_of(APART), threads=2) as two:
            one.step(20)
            two.step(20)
            yield one, two


def test_a_spawn_leaves_every_bystander_bit_identical():
    with _twins() as (quiet, busy):
        newcomer = busy.spawn(creature_entry("d", 30.0, goal=(30.0, 3.0)))
        quiet.step(90)
        busy.step(90)
        for name in ("a", "b", "c"):
            assert np.array_equal(_bodies(quiet, name), _bodies(busy, name)), name
        # the newcomer is a creature like the others: it crawled toward its goal
        start = np.array([30.0, 0.0])
        moved = busy.component(newcomer, Transform).pos[:2] - start
        assert moved[1] > 0.05
        assert busy.physics.compiles == 1  # same morphology: no model compiled


def test_a_despawn_leaves_every_bystander_bit_identical():
    with _twins() as (kept, cut):
        cut.despawn(cut.creature("b"))
        kept.step(90)
        cut.step(90)
        for name in ("a", "c"):
            assert np.array_equal(_bodies(kept, name), _bodies(cut, name)), name
        assert [c.name for _, c in cut.query(Creature)] == ["a", "c"]
        assert len(cut.physics) == 2
        # every row of the removed creature left every store
        loco_rows = {name: len(store) for name, store in cut.stores.items()}
        assert loco_rows["tentacles"] == loco_rows["locomotion.tentacles"] == 10
        assert loco_rows["creatures"] == loco_rows["locomotion.creatures"] == 2
        assert loco_rows["motors"] == 60 and loco_rows["transforms"] == 62


def test_components_made_before_a_despawn_still_find_their_rows():
    with World.from_scene(scene_of(APART)) as world:
        c = world.component(world.creature("c"), Creature)
        first_link = world.component(c.tentacles[0], Tentacle).links[0]
        motor = world.component(first_link, Motor)
        motor.strength = 7.25
        pose = world.component(world.creature("c"), Transform)
        before = np.array(pose.pos)
        world.despawn(world.creature("a"))
        assert motor.strength == 7.25
        assert np.array_equal(pose.pos, before)
        assert world.creatures.mantle_row[c.row] == pose.row
        world.step(5)  # the physics reads the renumbered rows
        assert world.physics.view_of(c).creature == world.creature("c")


def test_despawn_then_spawn_reuses_the_batch_and_steps_on():
    with World.from_scene(scene_of(APART)) as world:
        world.step(10)
        spec = copy.deepcopy(world.creature_specs[world.creature("b")])
        world.despawn(world.creature("b"))
        again = world.spawn(spec, position=(6.0, 0.0))
        assert world.creature_name(again) == "b"
        assert world.physics.compiles == 1
        world.step(30)
        assert world.physics.health.recoveries == 0


def test_restoring_a_snapshot_from_before_a_spawn_removes_the_newcomer():
    with World.from_scene(scene_of(APART)) as world:
        world.step(10)
        snap = world.snapshot()
        world.step(40)
        expected = {name: _bodies(world, name) for name in ("a", "b", "c")}
        world.restore(snap)
        gone = []
        world.events.on("creature_despawned", lambda **e: gone.append(e["creature_name"]))
        world.spawn(creature_entry("d", 30.0, goal=(30.0, 3.0)))
        world.spawn({**creature_entry("e", -30.0), "tentacles": {"count": 7}})  # a new model
        world.step(25)
        world.restore(snap)
        assert sorted(gone) == ["d", "e"]
        assert [c.name for _, c in world.query(Creature)] == ["a", "b", "c"]
        world.step(40)  # as if the newcomers had never come
        for name, poses in expected.items():
            assert np.array_equal(_bodies(world, name), poses), name


def test_a_snapshot_naming_a_despawned_creature_is_refused_and_changes_nothing():
    from ecs_tentacles.snapshot import SnapshotMismatch

    with World.from_scene(scene_of(APART)) as world:
        snap = world.snapshot()
        world.despawn(world.creature("b"))
        newcomer = world.spawn(creature_entry("d", 30.0))
        with pytest.raises(SnapshotMismatch, match="creature 'b' was despawned since"):
            world.restore(snap)
        assert world.creature_name(newcomer) == "d"  # still there: nothing changed
        world.step(5)


def test_a_take_records_the_roster_per_frame(tmp_path):
    from ecs_tentacles.record.systems.record import Record
    from ecs_tentacles.take import Take

    with World.from_scene(scene_of(APART)) as world:
        record = world.add_system(Record())
        world.step(10)
        newcomer = world.spawn(creature_entry("d", 30.0, goal=(30.0, 3.0)))
        world.step(10)
        world.despawn(world.creature("b"))
        world.step(10)
        world.despawn(newcomer)
        world.step(5)
        path = tmp_path / "roster.npz"
        record.take().save(path)
    take = Take.load(path)  # checked as any take
    assert take.problem() is None
    names = [c["name"] for c in take.header["creatures"]]
    assert names == ["a", "b", "c", "d"]
    shown = take.visible()
    assert shown.shape == (36, 4)
    assert shown[:, [0, 2]].all()  # a and c: always there
    assert shown[:21, 1].all() and not shown[21:, 1].any()  # b: gone after frame 20
    assert not shown[:11, 3].any() and shown[11:31, 3].all() and not shown[31:, 3].any()
    mantle_b = take.header["creatures"][1]["mantle"]
    assert np.array_equal(take.pos[21:, mantle_b], np.repeat(take.pos[20:21, mantle_b], 15, 0))
    mantle_d = take.header["creatures"][3]["mantle"]
    held = take.pos[:11, mantle_d]  # before it came: the pose it came in
    assert np.array_equal(held, np.repeat(held[:1], 11, 0)) and held[0, 0] == 30.0
    assert not np.array_equal(take.pos[30, mantle_d], take.pos[11, mantle_d])  # it moved


def test_furred_bystanders_keep_their_fur_through_a_despawn_and_a_spawn():
    from ecs_tentacles.fur.stores import FurData

    with World.from_scene("fur_presets") as world, World.from_scene("fur_presets") as twin:
        world.step(60)
        twin.step(60)
        first = sorted(world.creature_specs)[0]  # the hedgehog: its guides come first
        world.despawn(first)
        world.step(1)
        twin.step(1)
        here, there = world.resource(FurData).curves, twin.resource(FurData).curves
        assert len(here) < len(there)
        assert np.array_equal(here, there[len(there) - len(here) :])  # dynamic strands too
        cat = copy.deepcopy(twin.creature_specs[sorted(twin.creature_specs)[1]])
        world.spawn(cat, position=(20.0, 20.0))
        world.step(1)
        twin.step(1)
        kept = len(here)
        assert np.array_equal(
            world.resource(FurData).curves[:kept], twin.resource(FurData).curves[-kept:]
        )
        world.step(10)
        assert world.physics.health.recoveries == 0


def test_a_threat_dropped_at_run_time_rouses_the_fur_of_creatures_near_it():
    from ecs_tentacles.fur.stores import FurData
    from ecs_tentacles.threats.data import ThreatData

    with World.from_scene("hedgehog_octopus") as world:
        world.step(30)
        emotion = world.resource(FurData)
        calm = float(emotion.emotions.level.max())
        hedgehog = world.component(sorted(world.creature_specs)[0], Transform).pos
        roach = world.resource(ThreatData).drop(world, [hedgehog[0] + 0.4, hedgehog[1]])
        world.step(60)
        assert float(emotion.emotions.level.max()) > calm + 0.3
        world.resource(ThreatData).remove(world, roach)
        world.step(5)
        assert roach not in world.resource(ThreatData).entities(world)


def test_a_despawned_creature_lets_go_of_the_ground_first():
    with World.from_scene("octopus") as world:
        world.step(120)
        held = int(world.suckers.attached.sum())
        assert held > 0
        reasons = []
        world.events.on("sucker_released", lambda **e: reasons.append(e["reason"]))
        world.despawn(world.creature("octopus"))
        assert reasons == ["despawn"] * held
        assert len(world.suckers) == 0 and len(world.physics) == 0
        world.step(5)  # an empty world steps on


def test_what_a_despawn_updates_in_place_equals_what_a_rebuild_makes():
    """The fast paths (contact proxies, motor target tables) against building afresh,
    after despawns and a spawn."""
    from ecs_tentacles.creator.crowd import crowd_scene

    with World.from_scene(crowd_scene(12, seed=3)) as world:
        world.step(3)
        for entity in sorted(world.creature_specs)[2:9:3]:
            world.despawn(entity)
        world.spawn({"name": "late", "tentacles": {"count": 4}}, position=(60.0, 0.0))
        proxies = world.physics.proxies
        fast = {name: getattr(proxies, name).copy() for name in ("rows", "owner", "start", "count")}
        index = [i.copy() for i in proxies.index]
        proxies.reindex()
        for name, values in fast.items():
            assert np.array_equal(values, getattr(proxies, name)), name
        assert all(np.array_equal(a, b) for a, b in zip(index, proxies.index, strict=True))
        targets = world.schedule["motor_targets"]
        kept = {name: getattr(targets, name).copy() for name in
                ("inner", "previous", "previous_of", "orient_share", "arch_shape")}  # fmt: skip
        targets.setup(world)
        for name, values in kept.items():
            assert np.array_equal(values, getattr(targets, name)), name


def test_a_newcomer_meets_the_creatures_there_through_contact():
    octopus = {"name": "a", "position": [0.0, 0.0], "goals": [{"position": [3.0, 0.0]}]}
    scene = scene_of([octopus])
    scene["avoidance"] = {"enabled": False}  # straight into each other, not around
    with World.from_scene(scene) as world:
        world.step(5)
        b = world.spawn({"name": "b", "goals": [{"position": [-3.0, 0.0]}]}, position=(2.2, 0))
        deepest, met = 0.0, 0
        for _ in range(400):  # head-on: they crawl into each other
            world.step(1)
            met = max(met, int(world.physics.proxies_used.max()))
            views = (world.physics.view_of(world.component(e, Creature)) for e in (b,))
            deepest = min(deepest, *(v.data.deepest_contact for v in views))
        assert met > 0  # each felt the other's bodies
        assert deepest > -0.01 and world.physics.health.recoveries == 0


def test_a_spawn_inside_a_rock_is_refused_or_moved_out_of_it():
    rock = {"obstacles": [{"shape": "box", "position": [5.0, 0.0, 0.5], "size": [2, 2, 1]}]}
    with World.from_scene({**scene_of(APART[:1]), "terrain": rock}) as world:
        with pytest.raises(SpawnError, match="overlaps an obstacle"):
            world.spawn(creature_entry("d", 5.0))
        moved = world.spawn(creature_entry("d", 5.0), on_overlap="move")
        x, y = world.component(moved, Transform).pos[:2]
        assert max(abs(x - 5.0), abs(y)) > 1.0  # out of the 2 m box
        world.step(20)
        assert world.physics.health.recoveries == 0


def test_models_rebuilt_after_a_body_plan_left_retire_its_empty_batch():
    with World.from_scene(scene_of(APART)) as world:
        odd = world.spawn({"name": "odd", "tentacles": {"count": 3}}, position=(30.0, 0.0))
        assert world.physics.compiles == 2
        world.despawn(odd)
        world.physics.rebuild_models(world)  # (a terrain edit): nobody left to build it from
        again = world.spawn({"name": "odd", "tentacles": {"count": 3}}, position=(30.0, 0.0))
        assert world.physics.compiles == 3  # a new batch for the shape
        assert world.physics.view_of(world.component(again, Creature)).batch.index == 2
        world.step(10)
        assert world.physics.health.recoveries == 0


def test_a_despawn_leaves_no_entity_the_creature_owned() -> None:
    """Links, suckers, tentacles, goals, fur controls and guides: every entity made for a
    creature goes with it (a left-over fur control was still drawn, and raised)."""
    import esper

    from ecs_tentacles.fur.components import FurControl

    with World.from_scene("hedgehog_octopus") as world:
        world.step(5)
        spec = copy.deepcopy(next(iter(world.creature_specs.values())))
        spec["goals"] = [{"position": [8.0, 3.0]}, {"position": [9.0, 0.0]}]
        before = world.create_entity()  # entity numbers count up: the spawn's lie between
        entity = world.spawn(spec, position=(8.0, 0.0))
        after = world.create_entity()
        made = [e for e in range(before + 1, after) if esper.entity_exists(e)]
        assert len(made) > 500  # the creature, its body, two goals, fur guides and controls
        controls = sum(1 for _ in world.query(FurControl))
        world.step(2)
        world.despawn(entity)
        world.activate()
        assert [e for e in made if esper.entity_exists(e)] == []
        assert sum(1 for _ in world.query(FurControl)) < controls
        for _, control in world.query(FurControl):
            assert control.row >= 0  # every control left belongs to a creature still here
        world.step(2)


def test_a_body_plan_whose_first_creature_left_still_gets_its_reduced_model():
    """The reduced model is compiled lazily, when a creature of the plan first drops to the
    reduced tier; it was built from the plan's first creature, gone by then (KeyError: the
    physics system failed and the sandbox froze)."""
    scene = {**scene_of(APART), "physics": {"lod": {"full": 1, "reduced": 64}}}
    seven = {**creature_entry("e", -30.0), "tentacles": {"count": 7, "links": 4}}
    with World.from_scene(scene) as world:
        snap = world.snapshot()
        world.step(5)
        world.despawn(world.spawn(seven))
        world.restore(snap)
        for i in range(6):
            world.spawn({**seven, "name": f"e{i}", "position": [-30.0 + 3 * i, 8.0]})
        world.step(30)
        assert world.lod.counts()["reduced"] >= 5
        assert world.physics.health.recoveries == 0
