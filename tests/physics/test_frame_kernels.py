"""The physics' bookkeeping kernels give numpy's numbers bit for bit."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.physics import backend as backend_module
from ecs_tentacles.physics import health as health_module
from ecs_tentacles.physics.state_layout import S
from ecs_tentacles.world import World
from tests.conftest import crawlers

SCENE = crawlers(4)


def test_servo_commands_are_numpys(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert backend_module.KERNELS.get() is not None  # numba comes with the dev extra
    world = make_world(SCENE)
    world.step(3)
    physics, motors = world.physics, world.motors
    physics.frozen[1] = True  # keeps what it had: neither path writes its row
    physics.soften[2] = 0.37  # just recovered: softer servos
    motors.strength *= np.linspace(0.5, 2.0, len(motors.strength))
    batch = physics.batches[0]
    index = batch.actuator_target_index.copy()
    index[0, 0] = motors.target.size + 5  # out of range: clipped, as np.take's mode="clip"
    batch.actuator_target_index = index
    written = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(backend_module.KERNELS, "backend", backend)
        for part in (batch.ctrl, batch.kp, batch.kv, batch.torque):
            part[:] = -7.0
        physics.write_controls(motors)
        written.append([batch.ctrl.copy(), batch.kp.copy(), batch.kv.copy(), batch.torque.copy()])
    for kernel, numpy in zip(*written, strict=True):
        assert_array_equal(kernel, numpy)
    row = int(physics.row_of[1])
    assert (written[0][1][row] == -7.0).all()  # the frozen creature's row untouched
    assert not (np.delete(written[0][1], row, axis=0) == -7.0).any()


def test_the_fastest_body_is_numpys(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert health_module.KERNELS.get() is not None
    world = make_world(SCENE)
    world.step(2)
    health = world.physics.health
    rng = np.random.default_rng(4)
    pos = world.transforms.pos + rng.normal(0.0, 0.05, world.transforms.pos.shape)
    pos[health.rows[health.start[3] + 2], 1] = np.nan  # creature 3: a pose not finite
    for active in (np.ones(4, bool), np.array([True, False, True, True])):
        found = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(health_module.KERNELS, "backend", backend)
            found.append(health._fastest(pos, active))
        assert_array_equal(found[0], found[1])
        assert np.isnan(found[0][3]) and (found[0][~active] == 0.0).all()
        assert (found[0][:3][active[:3]] > 0.0).all()


def test_the_poses_the_health_check_remembers_are_numpys_and_skip_replayed_creatures(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A replayed creature is never checked (promoted, `restart` sets its rows), so its
    bodies are not copied for the next check; everyone else's are, as numpy copies them."""
    from ecs_tentacles.numeric.untouched import untouched_zeros
    from ecs_tentacles.physics.tiers import FULL, KINEMATIC, REDUCED

    world = make_world(SCENE)
    world.step(2)
    health, tier = world.physics.health, world.physics.roster.tier
    pos = world.transforms.pos + 1.0
    for tiers in ([FULL, KINEMATIC, REDUCED, KINEMATIC], [FULL] * 4, [KINEMATIC] * 4):
        tier[:] = tiers
        found = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(health_module.KERNELS, "backend", backend)
            health.previous = untouched_zeros(pos.shape)  # as in a crowd with some replayed
            health.previous[:] = -7.0
            health._remember(pos)
            found.append(health.previous)
        assert_array_equal(found[0], found[1])
        for c in range(4):
            rows = health.rows[health.start[c] : health.start[c] + health.count[c]]
            want = -7.0 if tiers[c] == KINEMATIC else pos[rows]
            assert_array_equal(found[0][rows], np.broadcast_to(want, (len(rows), 3)))


def test_the_health_check_finds_the_same_faults_with_and_without_kernels(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    world = make_world(SCENE)
    world.step(12)
    physics = world.physics
    batch, health = physics.batches[0], physics.health
    row = [int(physics.row_of[i]) for i in range(4)]
    start = world.snapshot()
    deepest = batch.deepest.copy()  # a step's results, not in a snapshot

    def fault(case: int) -> None:
        if case == 1:
            batch.warnings[row[0], 3] = 1
        elif case == 2:
            batch.qvel[row[1], 7] = np.inf
        elif case == 3:
            batch.deepest[row[2]] = -2.0 * health.max_penetration
        elif case == 4:  # not stepped this frame (asleep): not its step's fault
            batch.qvel[row[2], 0] = np.nan
            physics.sleeping[2] = True

    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(health_module.KERNELS, "backend", backend)
        for case in range(5):
            world.restore(start)
            batch.deepest[:], batch.warnings[:] = deepest, 0
            fault(case)
            health.check(world, physics.time)
            found.append((sorted(health.failures), dict(health.causes)))
    assert found[:5] == found[5:]
    assert [failed for failed, _ in found[:5]] == [[], [0], [1], [2], []]
    assert [causes for _, causes in found[:5]] == [
        {},
        {"mujoco": 1},
        {"non-finite": 1},
        {"penetration": 1},
        {},
    ]


def test_sucker_switches_are_numpys(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    world = make_world(SCENE)
    world.step(3)
    physics, suckers = world.physics, world.suckers
    rng = np.random.default_rng(2)
    suckers.anchor[:] = rng.normal(size=suckers.anchor.shape)
    suckers.attached[:] = rng.random(len(suckers.attached)) < 0.5
    physics.frozen[2] = True  # keeps what it had: neither path writes its row
    batch = physics.batches[0]
    assert len(batch.equality_ids) and suckers.attached.any() and not suckers.attached.all()
    written = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(backend_module.KERNELS, "backend", backend)
        batch.anchor[:] = -7.0
        batch.state[:] = -7.0
        physics.write_suckers(suckers)
        written.append([batch.anchor.copy(), batch.state.copy()])
    for kernel, numpy in zip(*written, strict=True):
        assert kernel.tobytes() == numpy.tobytes()
    anchor, state = written[0]
    row = int(physics.row_of[2])
    assert (anchor[row] == -7.0).all() and not (np.delete(anchor, row, axis=0) == -7.0).any()
    switches = state[:, batch.slices[int(S.mjSTATE_EQ_ACTIVE)]]
    live = np.delete(np.arange(len(state)), row)
    assert set(np.unique(switches[live])) == {0.0, 1.0}


def test_the_poses_scatter_is_numpys(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Body poses copied into the Transform store where a batch's rows are not one run
    of store rows (several body plans, their creatures interleaved)."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import batch_poses as batch_module

    world = make_world(crowd_scene(16, seed=2))
    world.step(2)
    batches = world.physics.batches
    assert any(b.body_span() is None for b in batches)  # the scattered case is reached
    rng = np.random.default_rng(3)
    for b in batches:
        b.xpos[:] = rng.normal(size=b.xpos.shape)
        b.xquat[:] = rng.normal(size=b.xquat.shape)
    stores = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(batch_module.FRAME_KERNELS, "backend", backend)
        world.transforms.pos[:] = -7.0
        world.transforms.quat[:] = -7.0
        world.physics.sync(world.transforms)
        stores.append([world.transforms.pos.copy(), world.transforms.quat.copy()])
    for kernel, numpy in zip(*stores, strict=True):
        assert kernel.tobytes() == numpy.tobytes()
    for b in batches:
        assert np.array_equal(stores[0][0][b.body_rows], b.xpos)
