"""The rig's bind blocks follow spawns and despawns without binding every guide anew,
and always hold exactly what binding every guide anew gives."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from ecs_tentacles.fur import blocks as blocks_module
from ecs_tentacles.fur.bind import make_bind
from ecs_tentacles.fur.blocks import BindBlocks
from ecs_tentacles.fur.rig import PER_GUIDE
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.world import World


def _furred(name: str, x: float, preset: str, count: int) -> dict:
    return {
        "name": name,
        "position": [x, 0.0],
        "tentacles": {"count": 4, "links": 5},
        "fur": {"preset": preset, "groom": {"count": count, "seed": 3}},
    }


def _assert_same_as_binding_anew(world: World) -> None:
    fur = world.resource(FurData)
    binds: BindBlocks = world.schedule["rig"].binds
    fresh, bodies = make_bind(fur)
    np.testing.assert_array_equal(binds.bodies, bodies)
    whole = binds.whole
    for name in (*PER_GUIDE, "root", "basis", "shape_h"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(fresh, name), err_msg=name)
    starts = [rows.start for rows, _ in binds.blocks]
    stops = [rows.stop for rows, _ in binds.blocks]
    assert starts == [0, *stops[:-1]] and stops[-1] == len(fur.guides)
    assert all(
        len(bind) == rows.stop - rows.start <= blocks_module.BLOCK for rows, bind in binds.blocks
    )


def test_spawns_and_despawns_keep_the_bind_equal_to_binding_anew(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(blocks_module, "BLOCK", 64)  # many blocks, and creatures across them
    scene = {
        "version": 1,
        "creatures": [
            _furred("hog", 0.0, "hedgehog", 90),
            {"name": "bare", "position": [4.0, 0.0], "tentacles": {"count": 4, "links": 5}},
            _furred("cat", 8.0, "cat", 70),
            _furred("bird", 12.0, "bird", 40),
        ],
    }
    with World.from_scene(scene) as world:
        world.step(2)
        rig = world.schedule["rig"]
        _assert_same_as_binding_anew(world)
        spec = copy.deepcopy(world.creature_specs[world.creature("cat")])
        steps = [
            lambda: world.despawn(world.creature("bare")),  # no fur: bodies renumbered only
            lambda: world.despawn(world.creature("cat")),  # fur from the middle
            lambda: world.spawn(spec, position=(30.0, 0.0)),
            lambda: world.spawn(_furred("hog2", 0, "hedgehog", 150), position=(40.0, 0.0)),
            lambda: world.despawn(world.creature("hog")),  # the first guides
            lambda: world.spawn({"name": "bare2", "tentacles": {"count": 3}}, position=(50.0, 0.0)),
        ]
        for step in steps:
            version = world.resource(FurData).version
            step()
            assert rig.version == world.resource(FurData).version  # bound now, not next frame
            _assert_same_as_binding_anew(world)
            world.step(1)
            assert rig.version == world.resource(FurData).version or version < 0
        world.step(5)
        assert world.physics.health.recoveries == 0


def test_an_edit_before_a_spawn_still_reaches_the_bind():
    """An edit of the bind pose not yet bound (a touch) makes the roster change bind anew."""
    scene = {"version": 1, "creatures": [_furred("hog", 0.0, "hedgehog", 60)]}
    with World.from_scene(scene) as world:
        world.step(1)
        fur = world.resource(FurData)
        fur.guides.multiplier[:] = -fur.guides.multiplier
        fur.touch()
        world.spawn(_furred("cat", 0, "cat", 30), position=(10.0, 0.0))
        _assert_same_as_binding_anew(world)


def test_despawning_every_furred_creature_then_spawning_one_binds_it():
    scene = {"version": 1, "creatures": [_furred("hog", 0.0, "hedgehog", 60)]}
    with World.from_scene(scene) as world:
        world.step(1)
        world.despawn(world.creature("hog"))
        world.step(1)
        world.spawn(_furred("cat", 0, "cat", 30), position=(10.0, 0.0))
        world.step(1)
        _assert_same_as_binding_anew(world)
        assert np.isfinite(world.resource(FurData).curves).all()
        assert np.abs(world.resource(FurData).curves).max() > 1.0  # posed near x = 10


def _buffers(value: object, seen: dict[int, int]) -> None:
    """The distinct numpy buffers under `value` (arrays, binds, blocks): id -> bytes."""
    if isinstance(value, np.ndarray):
        base = value
        while isinstance(base.base, np.ndarray):
            base = base.base
        seen[id(base)] = base.nbytes
    elif isinstance(value, (list, tuple)):
        for item in value:
            _buffers(item, seen)
    elif hasattr(value, "__dict__"):
        for item in vars(value).values():
            _buffers(item, seen)


def test_the_rig_holds_its_bind_pose_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The blocks are the bind pose; the whole bind is joined only when asked (binding
    the dynamic strands asks), not kept beside them: a crowd's was a second copy."""
    monkeypatch.setattr(blocks_module, "BLOCK", 64)  # several blocks: joining copies
    scene = {"version": 1, "creatures": [_furred("hog", 0.0, "hedgehog", 90),
                                         _furred("cat", 4.0, "cat", 70)]}  # fmt: skip
    with World.from_scene(scene) as world:
        world.step(2)
        rig = world.schedule["rig"]
        assert rig.strands is not None  # (the cat's fur is dynamic: the whole was joined)
        held: dict[int, int] = {}
        _buffers(rig.binds, held)
        fresh, _ = make_bind(world.resource(FurData))
        once = sum(getattr(fresh, k).nbytes for k in (*PER_GUIDE, "root", "basis", "shape_h"))
        assert sum(held.values()) < 1.2 * once  # (and a few index arrays)
