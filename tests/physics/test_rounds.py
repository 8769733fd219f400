"""A frame with creatures near another: rounds in order, the rest stepped around them."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.physics.tiers import FULL
from ecs_tentacles.world import World

TIME = int(mujoco.mjtState.mjSTATE_TIME)


def _pair_and_others(others: int = 5) -> dict[str, Any]:
    """Two creatures whose tentacle tips are 3 cm apart, and `others` far from everyone."""
    creatures: list[dict[str, Any]] = [
        {"name": "a", "position": [0.0, 0.0], "tentacles": {"count": 3, "links": 4}},
        {
            "name": "b",
            "position": [0.7, 0.0],
            "heading_deg": 180,
            "tentacles": {"count": 3, "links": 4},
            "goals": [{"position": [-2.0, 0.0]}],  # it crawls into a
        },
    ]
    creatures += [
        {
            "name": f"far{i}",
            "position": [6.0 + 4.0 * i, 0.0],
            "tentacles": {"count": 3, "links": 4},
            "goals": [{"position": [6.0 + 4.0 * i, 2.0]}],
        }
        for i in range(others)
    ]
    return {"version": 1, "creatures": creatures}


@pytest.mark.parametrize("threads", [1, 2])
def test_ready_steps_a_creature_of_the_rest_before_it_returns(
    make_world: Callable[..., World], threads: int
) -> None:
    world = make_world(_pair_and_others(), threads=threads)
    world.step(2)
    physics = world.physics
    physics.proxies.update(world.transforms)
    near = physics.proxies_used > 0
    assert near[:2].all() and not near[2:].any()
    far = 2  # a creature of the rest
    batch, row = physics.batches[int(physics.batch_of[far])], int(physics.row_of[far])
    start = batch.state[row].copy()
    seen: list[np.ndarray] = []

    def between(ready: Callable[[np.ndarray], None]) -> None:
        ready(np.array([far]))  # as the proxies' refresh does before it reads or writes it
        seen.append(batch.state[row].copy())

    substeps = world.settings.substeps
    physics.step(substeps, rounds=4, between=between)
    assert len(seen) == 3  # between the four rounds
    assert not np.array_equal(seen[0], start)  # it took its steps before ready returned
    for state in seen:  # and no more after
        assert_array_equal(state, batch.state[row])


def test_a_pair_that_meets_moves_the_same_on_one_and_two_threads(
    make_world: Callable[..., World],
) -> None:
    runs, near_frames = [], []
    for threads in (1, 2):
        world = make_world(_pair_and_others(), threads=threads)
        poses, near = [], 0
        for _ in range(40):
            world.step(1)
            near += bool(world.physics.proxies.in_use)
            poses.append(world.transforms.pos.copy())
        assert (world.physics.tier == FULL).all()
        runs.append(np.array(poses))
        near_frames.append(near)
    assert near_frames[0] == near_frames[1] >= 30  # the pair stepped in rounds
    assert_array_equal(runs[0], runs[1])


@pytest.mark.parametrize("threads", [1, 2])
def test_reduced_creatures_that_meet_move_the_same_without_the_idle_rounds(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch, threads: int
) -> None:
    """Past the full budget the pair steps REDUCED: its one step a frame (two, near) falls
    in one of the four rounds, so the three others, and the proxies' catch-ups before
    them, step nothing and are left out; every pose, joint, speed and contact as with
    them."""
    from ecs_tentacles.physics import backend
    from ecs_tentacles.physics.tiers import REDUCED

    runs, refreshes = [], []
    for skip in (False, True):
        monkeypatch.setattr(backend, "SKIP_IDLE_ROUNDS", skip)
        world = make_world(_pair_and_others(others=8), threads=threads)
        proxies, counted = world.physics.proxies, [0]
        refresh = proxies.refresh

        def counting(*args: Any, refresh: Any = refresh, counted: list[int] = counted) -> None:
            counted[0] += 1
            refresh(*args)

        monkeypatch.setattr(proxies, "refresh", counting)
        frames, near = [], 0
        for _ in range(40):
            world.step(1)
            near += bool(proxies.in_use)
            motion = []
            for batch in world.physics.batches:
                for part in (mujoco.mjtState.mjSTATE_QPOS, mujoco.mjtState.mjSTATE_QVEL):
                    motion.append(batch.state[:, batch.slices[int(part)]].copy())
                motion.append(batch.deepest.copy())
            frames.append((world.transforms.pos.copy(), world.transforms.quat.copy(), *motion))
        assert (world.physics.tier == REDUCED).all() and near >= 30  # met, reduced
        runs.append(frames)
        refreshes.append(counted[0])
    assert refreshes[0] >= 3 * 30 and refreshes[1] == 0  # three catch-ups a frame, then none
    for with_rounds, without in zip(*runs, strict=True):
        for a, b in zip(with_rounds, without, strict=True):
            assert_array_equal(a, b)


def test_reduced_creatures_that_meet_take_their_step_at_three_substeps_a_frame(
    make_world: Callable[..., World],
) -> None:
    """At 3 substeps a frame (200 fps: within the schema's 2.5 ms step) the rounds split
    the full tier's steps 1, 1, 0, 1 and the reduced tier's one step falls in the third
    round, the one with no full step: the pair that meets still takes it every frame."""
    from ecs_tentacles.physics.tiers import REDUCED

    scene = _pair_and_others(others=8)
    scene["physics"] = {"fps": 200, "substeps": 3}
    world = make_world(scene)
    physics = world.physics
    near = 0
    for _ in range(30):
        world.step(1)
        near += bool(physics.proxies.in_use)
        for index in (0, 1):  # the pair's clocks: stepped to the world's
            batch, row = physics.batches[int(physics.batch_of[index])], int(physics.row_of[index])
            clock = batch.state[row, batch.slices[TIME]]
            assert clock[0] == pytest.approx(physics.time)  # (it stood still at 0 before)
    assert (physics.tier == REDUCED).all() and near >= 5  # stepped in rounds


def test_round_steps_keep_every_step_and_leave_out_the_rounds_nobody_near_takes() -> None:
    from ecs_tentacles.physics.rounds import round_steps
    from ecs_tentacles.physics.tiers import REDUCED, reduced_substeps

    for substeps in range(1, 101):  # the schema's substeps: no step lost in any split
        reduced = reduced_substeps(substeps)
        parts = round_steps(substeps, reduced, 4)
        assert sum(p[FULL] for p in parts) == substeps
        assert sum(p[REDUCED] for p in parts) == reduced
        assert all(p[FULL] or p[REDUCED] for p in parts)
    assert round_steps(3, 1, 4) == [{FULL: 1, REDUCED: 0}, {FULL: 1, REDUCED: 0},
                                    {FULL: 0, REDUCED: 1}, {FULL: 1, REDUCED: 0}]  # fmt: skip
    assert round_steps(8, 1, 4, [REDUCED]) == [{FULL: 2, REDUCED: 1}]  # only REDUCED near
    assert len(round_steps(8, 1, 4, [FULL, REDUCED])) == 4  # a FULL one near: every round
