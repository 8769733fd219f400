"""Placing late: a crowd replayed from its first frame holds no memory for the state and
pose rows of the creatures it never steps, and a creature placed late (promoted, spawned
beside, snapshotted, despawned) moves exactly as when every row was placed at the build."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.physics import backend, heap
from ecs_tentacles.physics.tiers import KINEMATIC
from ecs_tentacles.snapshot import restore, take
from ecs_tentacles.world import World

pytestmark = pytest.mark.skipif(
    heap.resident_bytes(np.zeros(1)) is None, reason="mincore (Linux) tells residency"
)


def _scene(count: int) -> dict[str, Any]:
    from ecs_tentacles.creator.crowd import crowd_scene

    scene = crowd_scene(count, seed=4, uniform=True)
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    return dict(scene)


def _whole_pages_resident(table: np.ndarray, row: int) -> int:
    """Resident bytes of the pages lying wholly inside row `row` of `table`."""
    page = 4096
    start = int(table.ctypes.data) + int(row) * table[0].nbytes
    first = -(-start // page) * page
    end = (start + table[0].nbytes) // page * page
    if end <= first:
        return 0
    inside = np.frombuffer(
        (np.ctypeslib.as_ctypes_type(np.uint8) * (end - first)).from_address(first), np.uint8
    )
    return heap.resident_bytes(inside) or 0


def test_a_crowd_replayed_from_the_start_holds_no_pages_of_the_rows_it_never_steps(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene(40))
    world.step(15)
    (batch,) = world.physics.batches
    replayed = world.physics.tier[batch.members] == KINEMATIC
    assert batch.unplaced is not None
    never = np.flatnonzero(batch.unplaced)
    assert set(never) <= set(np.flatnonzero(replayed)) and len(never) >= 30
    # a state row spans whole pages: none of those rows' is resident, every stepped one's is
    assert batch.state[0].nbytes > 2 * 4096
    assert sum(_whole_pages_resident(batch.state, row) for row in never) == 0
    assert all(_whole_pages_resident(batch.state, row) > 0 for row in np.flatnonzero(~replayed))
    placed = len(batch) - len(never)
    for table in (batch.xpos, batch.xquat):  # a pose row is within two pages
        assert table[0].nbytes < 4096
        assert (heap.resident_bytes(table) or 0) <= 2 * 4096 * placed < table.nbytes / 2
    # read through a view, a row is placed where the build meant, its shown poses kept
    row = int(never[0])
    index = int(batch.members[row])
    shown = batch.poses(row)
    view = world.physics.views[index]
    assert view.data.qpos[2] > 0.0 and not batch.unplaced[row]
    assert_array_equal(batch.poses(row)[0], shown[0])


def _run(make_world: Callable[..., World], late: bool) -> list[np.ndarray]:
    """A replayed crowd: a creature replayed from the start promoted, one spawned into
    its batch, a snapshot restored, a never-stepped creature despawned; per frame the
    store's poses and the stepped rows' state."""
    backend.PLACE_LATE = late
    world = make_world(_scene(10))
    seen: list[np.ndarray] = []

    def frames(count: int) -> None:
        for _ in range(count):
            world.step(1)
            stepped = world.physics.tier != KINEMATIC
            states = [b.state[stepped[b.members]] for b in world.physics.batches if len(b)]
            seen.extend([world.transforms.pos.copy(), world.transforms.quat.copy(), *states])

    frames(5)
    replayed = np.flatnonzero(world.physics.tier == KINEMATIC)
    (batch,) = world.physics.batches
    assert (batch.unplaced is not None) == late
    hero = int(world.physics.roster.entity[replayed[0]])
    index = world.lod.index(hero)
    shown = world.physics.batches[0].poses(int(world.physics.row_of[index]))[0][0]
    world.lod.promote(hero)
    frames(5)
    assert world.lod.tier_of(hero) == "full"
    mantle = world.physics.batches[0].poses(int(world.physics.row_of[index]))[0][0]
    assert np.linalg.norm(mantle[:2] - shown[:2]) > 1e-3  # it crawls on from where shown
    late_one = {**_scene(1)["creatures"][0], "name": "late", "goals": [{"position": [30.0, 0.0]}]}
    world.spawn(late_one, position=(-30.0, 0.0))
    frames(3)
    saved = take(world)
    frames(6)
    restore(world, saved)
    frames(6)
    gone = int(world.physics.roster.entity[replayed[-1]])
    world.despawn(gone)
    frames(6)
    return seen


def test_a_creature_placed_late_moves_as_one_placed_at_the_build(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(backend, "PLACE_LATE", True)
    runs = [_run(make_world, late) for late in (False, True)]
    assert len(runs[0]) == len(runs[1])
    for old, new in zip(*runs, strict=True):
        assert_array_equal(old, new)
