"""A batch's rows placed at once (`Batch.place_rows`, the build's) hold the state and
poses that placing each row alone (`Batch.place`, a spawn's) gives, bit for bit. (The
build as a whole is compared with worlds built before: `tests/creatures/test_build_digest.py`.)"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.world import World


def placed_both_ways(scene: Any) -> list[tuple[np.ndarray, ...]]:
    """Each batch's state and poses with its rows placed at once at poses of their own,
    then as `place` gives them row by row; after some frames stepped (the scratch data
    holds a moving row's, not a fresh one's)."""
    world = World.from_scene(scene, threads=1)
    try:
        world.step(3)
        rng = np.random.default_rng(8)
        found = []
        for batch in world.physics.batches:
            n = len(batch)
            pos = rng.uniform((-5.0, -5.0, 0.1), (5.0, 5.0, 0.3), (n, 3))
            quat = rng.normal(size=(n, 4))
            quat /= np.linalg.norm(quat, axis=1)[:, None]
            rows = rng.permutation(n)
            batch.forward(0)  # the scratch data holds a stepped row's state, forces
            batch.place_rows(rows, pos, quat)
            at_once = (batch.state.copy(), batch.xpos.copy(), batch.xquat.copy())
            for row, at, turn in zip(rows, pos, quat, strict=True):
                batch.place(int(row), at.copy(), turn.copy())
            found.append((*at_once, batch.state, batch.xpos, batch.xquat))
        return found
    finally:
        world.close()


@pytest.mark.parametrize(
    ("scene", "plans"),
    [
        pytest.param(crowd_scene(64, 3, uniform=True), 1, id="uniform-64"),
        pytest.param(crowd_scene(24, 5, idle=0.25, species=4), 4, id="varied-24"),
    ],
)
def test_rows_placed_at_once_are_the_rows_placed_alone(scene: Any, plans: int) -> None:
    batches = placed_both_ways(scene)
    assert len(batches) == plans
    for state, xpos, xquat, state_alone, xpos_alone, xquat_alone in batches:
        assert state.tobytes() == state_alone.tobytes()
        assert xpos.tobytes() == xpos_alone.tobytes()
        assert xquat.tobytes() == xquat_alone.tobytes()
        assert len(np.unique(xpos[:, 0], axis=0)) == len(xpos)  # every row its own place
