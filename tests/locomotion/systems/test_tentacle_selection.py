"""tentacle_selection: push or pull by the thesis's test, who drives, aborts, no goal."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.actions import Kind, Mode, drive_sequence
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.locomotion.systems.tentacle_selection import (
    KERNELS,
    STROKE_SECONDS,
    TentacleSelection,
    classify,
)
from ecs_tentacles.world import World
from tests.conftest import ByBackend, creature_scene


def _scene(
    gait: str, goal: list[float] | None, count: int = 4, links: int = 4, **locomotion: Any
) -> dict[str, Any]:
    scene = creature_scene(count=count, links=links)
    scene["creatures"][0]["locomotion"] = {"gait": gait, **locomotion}
    if goal is not None:
        scene["creatures"][0]["goals"] = [{"position": goal}]
    return scene


def _names(mode: Mode) -> list[str]:
    return [action.kind.name.lower() for action in drive_sequence(mode, 0.5, 1.0)]


def _unit(degrees: float) -> list[float]:
    angle = np.radians(degrees)
    return [np.cos(angle), np.sin(angle)]


# -- classify ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("degrees", "pull"),
    [
        (0.0, True),
        (45.0, True),
        (-45.0, True),
        (89.9, True),
        (-89.9, True),
        (90.1, False),
        (-90.1, False),
        (135.0, False),
        (-135.0, False),
        (180.0, False),
    ],
)
@pytest.mark.parametrize("base_degrees", [0.0, 30.0, 200.0])
def test_classify_pulls_within_a_right_angle(
    degrees: float, pull: bool, base_degrees: float
) -> None:
    goal = np.array([_unit(base_degrees + degrees)])
    base = np.array([_unit(base_degrees)])
    assert classify(goal, base)[0].tolist() == [pull]


def test_classify_counts_the_right_angle_itself_as_pull() -> None:
    # cos(pi/2) is 6e-17, not 0: both signs of that rounding must still pull
    quarter = np.pi / 2
    goal = np.array(
        [
            [np.cos(quarter), np.sin(quarter)],
            [np.cos(-quarter), np.sin(-quarter)],
            [0.0, 1.0],
            [0.0, -1.0],
            [1.0, 0.0],
            [np.cos(3 * quarter), np.sin(3 * quarter)],  # -1.8e-16 . [1, 0]
        ]
    )
    base = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 0.0]])
    assert classify(goal, base)[0].tolist() == [True] * 6


def test_classify_works_row_by_row() -> None:
    goal = np.array([_unit(0.0), _unit(0.0), _unit(90.0), _unit(90.0)])
    base = np.array([_unit(10.0), _unit(170.0), _unit(100.0), _unit(-100.0)])
    assert classify(goal, base)[0].tolist() == [True, False, True, False]


def test_classify_ignores_lengths_and_gives_the_cosine() -> None:
    # process passes raw mantle -> goal and mantle -> base vectors, metres long or short
    goal = np.array([[3.0, 0.0], [0.02, 0.0], [-5.0, 5.0]])
    base = np.array([[0.1, 0.1], [0.0, -0.3], [0.4, 0.0]])
    pull, cos = classify(goal, base)
    assert pull.tolist() == [True, True, False]
    np.testing.assert_allclose(cos, [np.sqrt(0.5), 0.0, -np.sqrt(0.5)], rtol=1e-15, atol=1e-15)


# -- in a world -------------------------------------------------------------------------


@pytest.mark.parametrize(("goal", "mode"), [([1.5, 0.0], Mode.PULL), ([-1.5, 0.0], Mode.PUSH)])
def test_cyclic_first_stroke_pulls_toward_and_pushes_away(
    make_world: Callable[..., World], goal: list[float], mode: Mode
) -> None:
    world = make_world(_scene("cyclic", goal))
    octo = world.creature("octo")
    world.step(1)
    t = world.stores["locomotion.tentacles"]
    assert t.driving.tolist() == [True, False, False, False]
    assert t.mode.tolist() == [mode, Mode.NONE, Mode.NONE, Mode.NONE]
    assert world.resource(Locomotion).queue(octo, 0) == _names(mode)
    assert _names(Mode.PULL) == ["extend", "attach", "pull", "detach"]
    assert _names(Mode.PUSH) == ["compress", "attach", "push", "detach"]
    assert [world.resource(Locomotion).queue(octo, k) for k in (1, 2, 3)] == [["idle"]] * 3
    assert t.started.tolist() == [0.0, -np.inf, -np.inf, -np.inf]


def test_coordinated_first_stroke_orients_then_pulls(make_world: Callable[..., World]) -> None:
    world = make_world(_scene("coordinated", [1.5, 0.0]))
    octo = world.creature("octo")
    world.step(1)
    assert world.stores["locomotion.tentacles"].driving.tolist() == [True, False, False, False]
    assert world.stores["locomotion.tentacles"].mode.tolist() == [
        Mode.PULL,
        Mode.NONE,
        Mode.NONE,
        Mode.NONE,
    ]
    assert world.resource(Locomotion).queue(octo, 0) == ["orient", *_names(Mode.PULL), "settle"]


def test_coordinated_goal_behind_pulls_with_the_far_tentacle(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene("coordinated", [-1.5, 0.0]))
    octo = world.creature("octo")
    world.step(1)
    assert world.stores["locomotion.tentacles"].driving.tolist() == [False, False, True, False]
    assert world.stores["locomotion.tentacles"].mode.tolist() == [
        Mode.NONE,
        Mode.NONE,
        Mode.PULL,
        Mode.NONE,
    ]
    assert world.resource(Locomotion).queue(octo, 2) == ["orient", *_names(Mode.PULL), "settle"]


def test_each_creature_drives_on_its_own(make_world: Callable[..., World]) -> None:
    def creature(name: str, position: list[float], count: int, **more: Any) -> dict[str, Any]:
        return {
            "name": name,
            "position": position,
            "tentacles": {"count": count, "links": 3},
            **more,
        }

    scene = {
        "version": 1,
        "creatures": [
            creature("a", [0, 0], 3, locomotion={"gait": "cyclic"}, goals=[{"position": [-2, 0]}]),
            creature("b", [3, 0], 4, goals=[{"position": [3, 2]}]),  # coordinated
            creature("c", [-3, 3], 2),  # no goal
        ],
    }
    world = make_world(scene)
    world.step(1)
    a, b, c = (world.creature(name) for name in "abc")
    assert world.resource(Locomotion).actions(a) == [
        "compress",
        "idle",
        "idle",
    ]  # +x pushes from -x
    assert world.resource(Locomotion).actions(b) == [
        "idle",
        "orient",
        "idle",
        "idle",
    ]  # +y pulls to +y
    assert world.resource(Locomotion).actions(c) == ["idle", "idle"]
    assert world.stores["locomotion.tentacles"].mode.tolist() == [
        Mode.PUSH, Mode.NONE, Mode.NONE,
        Mode.NONE, Mode.PULL, Mode.NONE, Mode.NONE,
        Mode.NONE, Mode.NONE,
    ]  # fmt: skip


def _new_drivers(world: World, frames: int) -> list[tuple[int, Mode]]:
    """Step `frames` frames; (tentacle, mode) of each drive that starts, in order."""
    started: list[tuple[int, Mode]] = []
    for _ in range(frames):
        before = world.stores["locomotion.tentacles"].driving.copy()
        world.step(1)
        for row in np.flatnonzero(world.stores["locomotion.tentacles"].driving & ~before):
            started.append((int(row), Mode(int(world.stores["locomotion.tentacles"].mode[row]))))
    return started


def test_cyclic_keeps_the_queued_stroke_when_the_goal_changes_sides(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene("cyclic", [1.5, 0.0]))
    octo = world.creature("octo")
    world.step(5)
    assert world.resource(Locomotion).queue(octo, 0) == _names(Mode.PULL)
    # behind and a little to the right: tentacle 1 (+y) now pushes, tentacle 2 (-x) pulls
    world.resource(GoalBook).set(octo, [-1.5, -0.5])
    world.step(1)
    assert world.stores["locomotion.tentacles"].driving.tolist() == [True, False, False, False]
    assert world.stores["locomotion.tentacles"].mode[0] == Mode.PULL
    assert world.resource(Locomotion).queue(octo, 0) == _names(Mode.PULL)
    assert _new_drivers(world, 180) == [(1, Mode.PUSH), (2, Mode.PULL)]


def test_coordinated_driver_aborts_when_the_goal_changes_sides(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene("coordinated", [1.5, 0.0]))
    octo = world.creature("octo")
    world.step(10)
    assert world.stores["locomotion.tentacles"].driving.tolist() == [True, False, False, False]
    assert world.stores["locomotion.tentacles"].mode[0] == Mode.PULL
    world.resource(GoalBook).set(octo, [-1.5, 0.0])
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["detach", "settle"]
    assert world.stores["locomotion.tentacles"].driving.tolist() == [False, False, False, False]
    assert world.stores["locomotion.tentacles"].mode.tolist() == [Mode.NONE] * 4
    # the next drive starts one stagger after the first, with the tentacle now facing the goal
    stagger_frames = int(np.ceil(STROKE_SECONDS / 2 * world.settings.fps))
    frames = stagger_frames - world.frame
    assert _new_drivers(world, frames) == []
    mantle = world.transforms.pos[world.creatures.mantle_row[0], :2]
    base = world.transforms.pos[world.tentacles.base_row[2], :2]
    goal_dir = (np.array([-1.5, 0.0]) - mantle) / np.linalg.norm([-1.5, 0.0] - mantle)
    base_dir = (base - mantle) / np.linalg.norm(base - mantle)
    assert classify(goal_dir[None], base_dir[None])[0].tolist() == [True]
    assert _new_drivers(world, 1) == [(2, Mode.PULL)]
    assert world.resource(Locomotion).queue(octo, 2) == ["orient", *_names(Mode.PULL), "settle"]


def test_no_goal_stops_the_drive_and_every_tentacle_idles(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_scene("coordinated", [1.5, 0.0], links=6))
    octo = world.creature("octo")
    released: list[str] = []
    world.events.on("sucker_released", lambda **kw: released.append(kw["reason"]))
    tip = world.tentacles.tip_sucker[0]
    for _ in range(60):  # until tentacle 0 grips for its pull
        world.step(1)
        if world.stores["locomotion.tentacles"].action[0] == Kind.PULL:
            break
    assert world.stores["locomotion.tentacles"].action[0] == Kind.PULL
    assert world.suckers.attached[tip]
    assert world.stores["locomotion.tentacles"].driving.tolist() == [
        True,
        False,
        True,
        False,
    ]  # 2 pushes too
    world.resource(GoalBook).clear(octo)
    world.step(1)
    assert world.resource(Locomotion).queue(octo, 0) == ["detach", "settle"]
    assert world.resource(Locomotion).queue(octo, 2) == ["detach", "settle"]
    assert world.stores["locomotion.tentacles"].driving.tolist() == [False] * 4
    assert released == ["command"]
    assert not world.suckers.attached[tip]
    world.step(30)
    assert world.resource(Locomotion).actions(octo) == ["idle"] * 4
    assert world.stores["locomotion.tentacles"].driving.tolist() == [False] * 4
    assert world.stores["locomotion.tentacles"].mode.tolist() == [Mode.NONE] * 4
    assert [world.resource(Locomotion).queue(octo, k) for k in range(4)] == [["idle"]] * 4
    assert world.suckers.attached.tolist() == [False] * 4
    assert world.events.counts["sucker_released"] == 1


@pytest.mark.parametrize("drivers", [1, 3])
def test_coordinated_drivers_cap_and_stagger(
    make_world: Callable[..., World], drivers: int
) -> None:
    world = make_world(_scene("coordinated", [1.5, 0.0], count=8, links=3, drivers=drivers))
    t = world.stores["locomotion.tentacles"]
    stagger = STROKE_SECONDS / drivers
    most = 0
    starts: set[float] = set()
    for _ in range(180):
        world.step(1)
        driving = np.flatnonzero(t.driving)
        assert len(driving) <= drivers
        most = max(most, len(driving))
        times = np.sort(t.started[driving])
        assert (np.diff(times) >= stagger - 1e-9).all(), times  # out of phase
        starts.update(times.tolist())
    assert most == drivers
    assert min(starts) == 0.0  # the first drive starts on the first frame


# -- the kernel on the plane --------------------------------------------------------------


def test_the_kernel_gives_the_numpy_paths_vectors_and_choices_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A crossing crowd (avoidance turning some creatures' goal directions), every
    tentacle and some creatures' only: the same vectors, cosines and push/pull."""
    assert KERNELS.get() is not None  # numba comes with the dev extra
    world = make_world(crowd_scene(12, seed=1))
    world.step(90)
    system = next(s for s in world.schedule if isinstance(s, TentacleSelection))
    assert system.gaits.avoidance.any()  # some goal directions are turned
    driven = system.gaits.has_goal.copy()
    every = np.arange(len(world.tentacles))
    some = np.flatnonzero(world.tentacles.creature_row % 3 == 0)
    for live in (every, some):
        results = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(KERNELS, "backend", backend)
            results.append(system._classified(world, live, driven))
        for kernel, numpy_path in zip(*results, strict=True):
            np.testing.assert_array_equal(kernel, numpy_path)
        assert results[0][2][live].any() and not results[0][2][live].all()  # pulls and pushes


def test_a_crowd_chooses_the_same_strokes_with_and_without_the_kernel(
    worlds_by_backend: ByBackend,
) -> None:
    worlds_by_backend(KERNELS, crowd_scene(8, seed=1), 120)


def test_the_kernel_stops_and_starts_the_strokes_numpy_does(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every case of the decisions: goals lost, replayed creatures, both gaits, both modes,
    a goal on the wrong side, strokes not yet due."""
    world = make_world(crowd_scene(12, seed=1))
    world.step(60)
    system = next(s for s in world.schedule if isinstance(s, TentacleSelection))
    g, s = system.gaits, system.strokes
    creature = world.tentacles.creature_row
    rng = np.random.default_rng(8)
    g.gait[:] = np.where(np.arange(len(g.gait)) % 2, system.cyclic, system.coordinated)
    g.has_goal[[1, 4]] = False
    g.last_start[:] = world.time - rng.uniform(0.0, 4.0, len(g.last_start))
    s.driving[:] = rng.random(len(s.driving)) < 0.12
    s.mode[:] = np.where(rng.random(len(s.mode)) < 0.5, int(Mode.PULL), int(Mode.PUSH))
    cos = rng.uniform(-1.0, 1.0, len(creature))
    replayed = np.zeros(len(g.gait), bool)
    replayed[[2, 7]] = True
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(KERNELS, "backend", backend)
        aborts = system._aborts(creature, cos, replayed)
        first, ready = system._starts(world.time, creature, replayed)
        found.append([aborts.tolist(), first.tolist(), ready.tolist()])
    assert found[0] == found[1]
    aborts, first, ready = found[0]
    assert aborts and first and ready  # every decision taken somewhere
    assert not {2, 7} & ({int(creature[k]) for k in aborts} | set(first) | set(ready))
