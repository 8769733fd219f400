"""Physics health: injected blow-ups recover only the creature hit, and are reported."""

from __future__ import annotations

import json
import logging
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.cli import main
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.physics.heap import resident_bytes
from ecs_tentacles.world import World
from tests.conftest import crawlers

SCENE = crawlers(3, apart=4.0, links=5)


def _hit_strength(world: World) -> None:
    """One tentacle's servos far past sane, and their torque limit lifted: an explicit
    spring of kp 1e5 on links of ~1e-4 kg m^2 at 1/480 s steps (dt * sqrt(kp / I) ~ 60,
    stable only below 2) diverges in its first step on any CPU. Within the torque limit
    a blow-up depended on rounding: some CPUs rode it out."""
    rows = world.physics.views[1].actuator_motor_rows
    world.motors.strength[rows[:10]] = 1e5
    world.motors.max_torque[rows[:10]] = 1e12


def _hit_force(world: World) -> None:
    group = world.physics.views[1]
    group.data.xfrc_applied[group.body_ids[0], 2] = 1e7  # on the mantle, for one frame


def _hit_nan(world: World) -> None:
    world.physics.views[1].data.qvel[7] = np.nan


FAULTS = {"strength": _hit_strength, "force": _hit_force, "nan": _hit_nan}


@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_a_blow_up_recovers_only_the_creature_hit(
    fault: str, make_world: Callable[..., World]
) -> None:
    clean, hurt = make_world(SCENE), make_world(SCENE)
    events: list[dict[str, Any]] = []
    hurt.events.on("creature_recovered", lambda **e: events.append(e))
    for world in (clean, hurt):
        world.step(30)
    FAULTS[fault](hurt)
    hurt.step(1)
    if fault == "force":
        hurt.physics.views[1].data.xfrc_applied[:] = 0.0
    clean.step(1)
    clean.step(120)
    hurt.step(120)
    assert {e["creature"] for e in events} == {hurt.creature("c1")}
    # servos left at 1e5 keep shaking their creature (until it is frozen); one-off hits heal
    expected = len(events) if fault == "strength" else 1
    assert hurt.physics.health.recoveries == expected >= 1
    assert hurt.events.counts["creature_recovered"] == expected
    for k in (0, 2):  # the others never noticed
        rows = hurt.physics.views[k].body_rows
        assert_array_equal(hurt.transforms.pos[rows], clean.transforms.pos[rows])
    assert np.isfinite(hurt.transforms.pos).all()
    speed = np.linalg.norm(hurt.transforms.pos - clean.transforms.pos, axis=1)
    assert speed.max() < 0.5  # restored, not thrown across the scene


def test_a_teleport_never_reaches_a_goal(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    world.step(10)
    group = world.physics.views[0]
    goal = world.stores["locomotion.creatures"].goal[0]
    group.data.qpos[0:2] = goal[:2]  # jump into the goal between two frames
    world.step(5)
    assert world.events.counts["goal_reached"] == 0
    assert world.physics.health.causes == {"speed": 1}
    assert len(world.resource(GoalBook).path(world.creature("c0"))) == 1


def test_a_creature_that_keeps_failing_is_frozen(
    make_world: Callable[..., World], caplog: pytest.LogCaptureFixture
) -> None:
    world = make_world(SCENE)
    frozen: list[dict[str, Any]] = []
    world.events.on("creature_frozen", lambda **e: frozen.append(e))
    world.step(10)
    with caplog.at_level(logging.WARNING, logger="ecs_tentacles.physics"):
        for _ in range(3):
            _hit_nan(world)
            world.step(5)
    group = world.physics.views[1]
    assert group.frozen and world.physics.health.frozen == 1 and len(frozen) == 1
    [line] = [r.message for r in caplog.records if r.name == "ecs_tentacles.physics"]
    assert line.startswith("creature 'c1' frozen: 3 physics failures in 2.0 s (last: ")
    still = world.transforms.pos[group.body_rows].copy()
    world.step(30)
    assert_array_equal(world.transforms.pos[group.body_rows], still)
    assert world.physics.health.recoveries == 3  # frozen, not looping


FAULTY = """
import numpy as np
from ecs_tentacles.system import System

class BreakOne(System):
    '''Writes NaN into creature 0's velocities on frame 20.'''
    name = "break_one"
    after = ("physics",)
    before = ("physics_health",)

    def process(self, world, dt):
        if world.frame == 20:
            world.physics.views[0].data.qvel[0] = np.nan
"""


@pytest.fixture
def faulty_scene(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "faulty_system.py").write_text(textwrap.dedent(FAULTY))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    scene = {**SCENE, "systems": ["faulty_system:BreakOne"]}
    path = tmp_path / "faulty.json"
    path.write_text(json.dumps(scene))
    return path


def test_run_reports_recoveries_and_strict_exits_1(
    faulty_scene: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["run", str(faulty_scene), "--frames", "40", "--allow-systems", "--quiet"]
    assert main([*args, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["recoveries"], summary["recovery_causes"], summary["frozen"]) == (
        1,
        {"non-finite": 1},
        0,
    )
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "warning: physics recovered 1 times (non-finite 1), 0 creatures frozen" in err
    error = "error: physics recovered 1 times (non-finite 1), 0 creatures frozen\n"
    for extra in ([], ["--json"]):  # exit 1 says why, in one line, with or without --json
        assert main([*args, "--strict", *extra]) == 1
        assert capsys.readouterr().err == error
    assert not (faulty_scene.parent / "MUJOCO_LOG.TXT").exists()


def test_mujoco_messages_go_to_logging_not_a_file(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    make_world: Callable[..., World],
    caplog: pytest.LogCaptureFixture,
) -> None:
    monkeypatch.chdir(tmp_path)
    world = make_world(SCENE)
    causes: list[str] = []
    world.events.on("creature_recovered", lambda **e: causes.append(e["cause"]))
    with caplog.at_level(logging.WARNING, logger="ecs_tentacles.mujoco"):
        world.physics.views[2].data.qvel[0] = 1e12  # MuJoCo warns: bad qvel (> 1e10)
        world.step(2)
    assert any("QVEL" in r.message for r in caplog.records)
    assert world.physics.health.causes == {"mujoco": 1}
    assert len(causes) == 1 and "badqvel" in causes[0].split(" ", 1)[1].split(", ")
    assert list(tmp_path.iterdir()) == []


def test_bake_marks_recoveries_in_the_take_and_strict_writes_nothing(
    faulty_scene: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from ecs_tentacles.take import Take

    out = faulty_scene.parent / "take.npz"
    args = ["bake", str(faulty_scene), "--seconds", "1", "--allow-systems", "--quiet"]
    assert main([*args, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: physics recovered 1 times, 0 creatures frozen (take frames 21;" in err
    health = Take.load(out).header["health"]
    assert health == {
        "recoveries": 1,
        "frozen": 0,
        "events": [{"frame": 21, "creature": 0, "event": "recovered", "cause": "non-finite state"}],
    }
    strict = faulty_scene.parent / "strict.npz"
    assert main([*args, "--out", str(strict), "--strict"]) == 1
    assert not strict.exists()
    left = {p.name for p in faulty_scene.parent.iterdir()} - {"__pycache__"}
    assert left == {"faulty.json", "faulty_system.py", "take.npz"}  # no partial, no log


def test_an_allowed_speed_lets_one_creature_fly_for_a_while(
    make_world: Callable[..., World],
) -> None:
    def jump(world: World) -> None:  # 0.5 m in one frame: 30 m/s, over the scene's 12
        world.physics.views[0].data.qpos[2] += 0.5  # straight up: nothing is in the way
        world.step(1)

    world = make_world(SCENE)
    world.step(10)
    health = world.physics.health
    health.allow_speed(0, 40.0, world.time + 0.5)
    snap = world.snapshot()
    jump(world)
    assert health.recoveries == 0  # within what it was allowed
    world.step(40)  # the allowance ends
    jump(world)
    assert health.causes == {"speed": 1}
    world.restore(snap)  # the allowance is part of the state
    jump(world)
    assert world.physics.health.recoveries == 0
    with pytest.raises(ValueError, match="speed"):
        health.allow_speed(1, 0.0, 1.0)


def test_a_creature_promoted_from_replay_recovers_to_where_it_was_promoted(
    make_world: Callable[..., World],
) -> None:
    replayed = {"full": 0, "reduced": 0, "hold_seconds": 0}
    world = make_world({**crawlers(2, apart=4.0, links=5), "physics": {"lod": replayed}})
    creature = world.creature("c0")
    world.step(60)  # both replayed, through several saves: no saved state is kept for them
    assert world.lod.tier_of(creature) == "kinematic"
    health, view = world.physics.health, world.physics.views[0]
    assert len(health.saved[view.batch.index].pool) == 0
    rows = view.body_rows
    shown = world.transforms.pos[rows].copy()
    world.lod.promote(creature)
    world.step(1)  # promoted (its good states made where it is shown), one frame stepped
    assert world.lod.tier_of(creature) == "full"
    assert len(health.saved[view.batch.index].pool) == 1  # the one stepped creature's
    view.data.qvel[7] = np.nan
    events: list[dict[str, Any]] = []
    world.events.on("creature_recovered", lambda **e: events.append(e))
    world.step(1)
    assert [e["creature"] for e in events] == [creature]
    assert health.recoveries == 1
    back = world.transforms.pos[rows]
    assert np.isfinite(back).all()
    assert np.linalg.norm(back - shown, axis=1).max() <= 0.02  # where it was promoted


def test_a_blow_up_on_the_first_frame_goes_back_to_where_the_creature_was_built(
    make_world: Callable[..., World],
) -> None:
    """Until the first save every creature's good states are its start, kept once (not
    two copies a creature made at the build: 183 MB at 10,000 creatures, most of them
    replayed from the first frame on and never restored)."""
    world = make_world(SCENE)
    health, view = world.physics.health, world.physics.views[1]
    assert len(health.saved[view.batch.index].pool) == 0  # nothing doubled at the build
    built = world.transforms.pos[view.body_rows].copy()
    _hit_nan(world)
    world.step(1)
    assert health.recoveries == 1
    np.testing.assert_allclose(world.transforms.pos[view.body_rows], built, rtol=0, atol=1e-12)
    world.step(20)  # saves made since: the recovered creature steps on
    assert health.recoveries == 1


def test_replayed_creatures_take_no_servo_or_check_pages_and_a_promoted_one_gets_them(
    make_world: Callable[..., World],
) -> None:
    """The tables written for stepped creatures only (servo gains and torque limits,
    sleep's last commands, the check's last poses) hold no memory for a crowd replayed
    from its first frame; a creature promoted later gets its rows there, steps under its
    gains and is checked against where it was."""
    replayed = {"full": 0, "reduced": 0, "hold_seconds": 0}
    world = make_world({**crawlers(40, apart=4.0, links=5), "physics": {"lod": replayed}})
    world.step(3)
    physics = world.physics
    batch, health = physics.batches[0], physics.health
    tables = (batch.kp, batch.kv, batch.torque, physics.sleep.commands[0])
    if resident_bytes(batch.kp) is None:
        pytest.skip("mincore: Linux only")
    assert [resident_bytes(t) for t in tables] == [0, 0, 0, 0]
    assert resident_bytes(health.previous) == 0
    creature = world.creature("c7")
    view = physics.views[7]
    world.lod.promote(creature)
    world.step(1)
    assert world.lod.tier_of(creature) == "full"
    assert (batch.kp[view.row] > 0).any() and not batch.kp[np.arange(40) != view.row].any()
    assert all((resident_bytes(t) or 0) > 0 for t in tables)
    start = world.transforms.pos[view.body_rows[0]].copy()
    world.step(60)  # under its own servos: it crawls, and the check finds nothing wrong
    assert np.linalg.norm(world.transforms.pos[view.body_rows[0]] - start) > 0.005
    assert health.recoveries == 0
