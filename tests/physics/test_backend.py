"""MuJoCo backend: settling, servos, run-time gains, suckers, pose sync."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Creature, Link, Motor, Sucker, Tentacle, Transform
from ecs_tentacles.locomotion.grip import attach, release, sucker_points
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION, creature_scene


def _tentacle(world: World, k: int) -> Tentacle:
    creature = world.component(world.creature("octo"), Creature)
    return world.component(creature.tentacles[k], Tentacle)


def _joint(world: World, link_entity: int, hinge: str) -> int:
    link = world.component(link_entity, Link)
    tentacle = world.component(link.tentacle, Tentacle)
    name = f"t{tentacle.index}/l{link.index:02d}/{hinge}"
    return int(world.physics.views[0].model.joint(name).id)


def test_model_options(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2), plugins=NO_LOCOMOTION)
    model = world.physics.views[0].model
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert model.opt.timestep == world.settings.substep_dt == 1 / 480
    assert model.geom("ground").type == mujoco.mjtGeom.mjGEOM_PLANE
    assert model.geom("mantle").type == mujoco.mjtGeom.mjGEOM_CYLINDER
    assert model.geom("t2/l01").type == mujoco.mjtGeom.mjGEOM_CAPSULE
    assert not model.eq_active0.any()
    limit = np.radians(60.0)  # the default joint_limit_deg, compiled as radians
    assert_allclose(model.jnt_range[model.joint("t0/l01/curl").id], [-limit, limit])


def test_creature_settles_on_the_ground(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(), plugins=NO_LOCOMOTION)  # 8 tentacles x 10 links, r 0.025
    world.step(300)  # 5 simulated seconds
    data = world.physics.views[0].data
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    assert world.physics.health.recoveries == 0
    mantle = world.component(world.creature("octo"), Transform)
    # base link radius + half the mantle height: resting on its tentacles
    assert abs(mantle.pos[2] - (0.025 + 0.1)) < 0.005
    up = quat_rotate(mantle.quat, np.array([0.0, 0.0, 1.0]))
    assert up[2] > 0.999
    assert np.abs(data.qvel[:6]).max() < 0.01


@pytest.mark.parametrize(
    ("gravity", "link_index", "hinge", "target"),
    [
        ([0, 0, -9.81], 4, "curl", [-0.5, 0.0, 0.0]),  # lift the tip off the ground
        ([0, 0, 0], 2, "sweep", [0.0, 0.5, 0.0]),  # swing a middle link, weightless
    ],
)
def test_servo_reaches_its_target(
    make_world: Callable[..., World],
    gravity: list[float],
    link_index: int,
    hinge: str,
    target: list[float],
) -> None:
    scene = creature_scene(count=4, links=5)
    scene["physics"] = {"gravity": gravity}
    world = make_world(scene, plugins=NO_LOCOMOTION)
    link = _tentacle(world, 0).links[link_index]
    world.component(link, Motor).target = target
    world.step(120)
    group = world.physics.views[0]
    angle = group.data.qpos[group.model.jnt_qposadr[_joint(world, link, hinge)]]
    assert abs(angle - sum(target)) < 0.01


def test_strength_change_at_run_time_changes_the_servo_force(
    make_world: Callable[..., World],
) -> None:
    world = make_world(creature_scene(count=4, links=5), plugins=NO_LOCOMOTION)
    link = _tentacle(world, 1).links[0]
    motor = world.component(link, Motor)
    motor.target = [0.0, 0.4, 0.0]
    group = world.physics.views[0]
    actuator = int(group.model.actuator("t1/l00/sweep").id)
    joint = _joint(world, link, "sweep")

    def force_and_expected(kp: float, kv: float) -> tuple[float, float]:
        model, data = group.standalone()  # as the creature's next step sees it
        q = data.qpos[model.jnt_qposadr[joint]]
        qd = data.qvel[model.jnt_dofadr[joint]]
        return float(data.actuator_force[actuator]), float(kp * (0.4 - q) - kv * qd)

    kp, kv = motor.strength, motor.damping
    assert (kp, kv) == (25.0, 0.5)  # the scene defaults, on the base link (scale 1)
    world.step(1)
    assert_allclose(*force_and_expected(kp, kv), rtol=1e-9)
    motor.strength = 3 * kp
    motor.damping = 2 * kv
    world.step(1)
    assert group.standalone()[0].actuator_gainprm[actuator, 0] == 3 * kp
    assert group.model.actuator_gainprm[actuator, 0] == kp  # the shared model is untouched
    assert_allclose(*force_and_expected(3 * kp, 2 * kv), rtol=1e-9)
    force, before = force_and_expected(kp, kv)
    assert abs(force - before) > 0.1


def _wave_tentacle(world: World, tentacle: Tentacle, frames: int) -> np.ndarray:
    """Drive a tentacle's joints with a vigorous wave; return the tip sucker's path."""
    rows = [world.component(e, Motor).row for e in tentacle.links]
    sucker_row = world.component(tentacle.suckers[0], Sucker).row
    path = []
    for _ in range(frames):
        t = world.time
        world.motors.target[rows, 0] = 0.6 * np.sin(2 * np.pi * 1.5 * t + np.arange(len(rows)))
        world.motors.target[rows, 1] = 0.6 * np.cos(2 * np.pi * 1.5 * t)
        world.step(1)
        path.append(sucker_points(world)[sucker_row])
    return np.array(path)


def test_attached_sucker_pins_the_tip_and_release_frees_it(
    make_world: Callable[..., World],
) -> None:
    world = make_world(creature_scene(count=4, links=6), plugins=NO_LOCOMOTION)
    events: list[str] = []
    world.events.on("sucker_attached", lambda **kw: events.append("attached"))
    world.events.on("sucker_released", lambda **kw: events.append(kw["reason"]))
    world.step(30)
    tentacle = _tentacle(world, 0)
    sucker = world.component(tentacle.suckers[0], Sucker)
    attach(world, tentacle.suckers[0])
    anchor = sucker.anchor.copy()
    assert_allclose(anchor, sucker_points(world)[sucker.row])
    pinned = _wave_tentacle(world, tentacle, 120)
    assert np.linalg.norm(pinned - anchor, axis=1).max() < 0.005
    release(world, tentacle.suckers[0])
    free = _wave_tentacle(world, tentacle, 120)
    assert np.linalg.norm(free - anchor, axis=1).max() > 0.03
    assert events == ["attached", "command"]
    assert world.events.counts["sucker_attached"] == 1


def test_physics_sync_copies_poses_bit_for_bit(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=5, links=4), plugins=NO_LOCOMOTION)
    world.motors.target[:, 0] = 0.3
    world.step(20)
    data, ids = world.physics.views[0].data, world.physics.views[0].body_ids
    assert_array_equal(world.transforms.pos, data.xpos[ids])
    assert_array_equal(world.transforms.quat, data.xquat[ids])
    link = _tentacle(world, 3).links[2]
    body = world.physics.views[0].model.body("t3/l02").id
    assert_array_equal(world.component(link, Transform).pos, data.xpos[body])


def test_the_schemas_longest_tentacles_crawl_without_a_recovery(
    make_world: Callable[..., World],
) -> None:
    scene = {
        "version": 1,
        "creatures": [
            {
                "name": "long",
                "tentacles": {"count": 4, "links": 64},  # the schema's most links
                "goals": [{"position": [2.0, 0.0]}],
            }
        ],
    }
    world = make_world(scene)
    world.step(36)  # 0.6 s: past the half second they once froze within
    assert world.physics.health.recoveries == 0 and not world.physics.frozen.any()
    assert np.isfinite(world.transforms.pos).all()


def test_a_world_stepping_on_two_threads_keeps_blas_to_one(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    from threadpoolctl import threadpool_info

    from ecs_tentacles.physics import blas

    for name in blas.CHOSEN_BY_USER:
        monkeypatch.delenv(name, raising=False)
    make_world({"version": 1, "creatures": [{"name": "a"}, {"name": "b", "position": [2, 0]}]},
               threads=2)  # fmt: skip
    pools = [p for p in threadpool_info() if p["user_api"] == "blas"]
    assert pools and all(p["num_threads"] == 1 for p in pools)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")  # the user's choice stands
    assert blas.quiet_blas() is False
