"""suckers: grab at the ground during attach; let go on command, on stretch, on reach."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Creature, Sucker, Tentacle
from ecs_tentacles.locomotion.actions import Kind
from ecs_tentacles.locomotion.grip import sucker_points
from ecs_tentacles.locomotion.systems.suckers import ATTACH_HEIGHT
from ecs_tentacles.world import World
from tests.conftest import creature_scene


class Recorder:
    """Every sucker event, as (name, frame, payload)."""

    def __init__(self, world: World):
        self.world = world
        self.events: list[tuple[str, int, dict[str, Any]]] = []
        for name in ("sucker_attached", "sucker_released"):
            world.events.on(name, self._handler(name))

    def _handler(self, name: str) -> Callable[..., None]:
        def record(**payload: Any) -> None:
            self.events.append((name, self.world.frame, payload))

        return record

    def reasons(self) -> list[str]:
        return [p["reason"] for name, _, p in self.events if name == "sucker_released"]


def _world(make_world: Callable[..., World], **scene: Any) -> World:
    # no goal: the tentacles idle and only what a test writes changes their actions
    base = creature_scene(count=2)  # ten links: a straight tentacle's tip can touch down
    for key, value in scene.items():
        if key == "locomotion":
            base["creatures"][0]["locomotion"] = value
        else:
            base[key] = value
    return make_world(base)


def _tip_sucker(world: World, tentacle: int) -> int:
    creature = world.component(world.creature("octo"), Creature)
    return world.component(creature.tentacles[tentacle], Tentacle).suckers[-1]


def _hold(world: World, row: int, kind: Kind) -> None:
    """Give tentacle `row` the action `kind` for ever."""
    world.stores["locomotion.tentacles"].action[row] = kind
    world.stores["locomotion.tentacles"].duration[row] = np.inf
    world.stores["locomotion.tentacles"].timer[row] = 0.0


def _grab(world: World, row: int, frames: int = 40) -> np.ndarray:
    """Press tentacle `row` down until its tip grips; return where the tip was then."""
    _hold(world, row, Kind.ATTACH)
    tip = int(world.tentacles.tip_sucker[row])
    for _ in range(frames):
        before = sucker_points(world)[tip].copy()
        world.step(1)
        if world.suckers.attached[tip]:
            return before
    raise AssertionError(f"tentacle {row} never gripped")


def test_attach_only_near_the_ground(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=2)
    scene["physics"] = {"gravity": [0, 0, 0]}
    scene["creatures"][0]["position"] = [0, 0, 0.5]  # weightless, in the air
    world = make_world(scene)
    events = Recorder(world)
    _hold(world, 0, Kind.ATTACH)
    lowest = np.inf
    for _ in range(40):
        world.step(1)
        lowest = min(lowest, float(sucker_points(world)[:, 2].min()))
    assert lowest > 0.4
    assert world.suckers.attached.tolist() == [False, False]
    assert events.events == []


def test_tip_grabs_the_ground_where_it_touches(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    events = Recorder(world)
    world.step(5)
    tip = int(world.tentacles.tip_sucker[0])
    assert sucker_points(world)[tip, 2] > ATTACH_HEIGHT  # a straight tentacle's tip hovers
    world.step(20)
    assert events.events == []  # idle tentacles never grab, even where they touch down
    where = _grab(world, 0)
    assert where[2] <= ATTACH_HEIGHT
    sucker = world.component(_tip_sucker(world, 0), Sucker)
    assert sucker.attached
    assert_array_equal(sucker.anchor, where)
    assert [(name, p["sucker"]) for name, _, p in events.events] == [
        ("sucker_attached", _tip_sucker(world, 0))
    ]
    assert_array_equal(events.events[0][2]["anchor"], where)
    assert world.suckers.attached.tolist() == [True, False]
    world.step(10)  # the hold lasts while the tentacle grips; the tip stays put
    assert world.suckers.attached.tolist() == [True, False]
    assert np.linalg.norm(sucker_points(world)[tip] - where) < 0.01
    assert world.events.counts["sucker_attached"] == 1


@pytest.mark.parametrize("kind", [Kind.DETACH, Kind.SETTLE, Kind.IDLE, Kind.EXTEND])
def test_release_on_command(make_world: Callable[..., World], kind: Kind) -> None:
    world = _world(make_world)
    events = Recorder(world)
    _grab(world, 0)
    for holding in (Kind.PUSH, Kind.PULL, Kind.ATTACH):
        _hold(world, 0, holding)
        world.step(1)
        assert world.suckers.attached.tolist() == [True, False], holding
    _hold(world, 0, kind)
    frame = world.frame
    world.step(1)
    assert world.suckers.attached.tolist() == [False, False]
    assert [(name, f) for name, f, _ in events.events] == [
        ("sucker_attached", events.events[0][1]),
        ("sucker_released", frame),
    ]
    assert events.reasons() == ["command"]
    assert events.events[1][2]["sucker"] == _tip_sucker(world, 0)
    assert world.events.counts["sucker_released"] == 1


def test_release_on_stretch(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    events = Recorder(world)
    _grab(world, 0)
    row = int(world.tentacles.tip_sucker[0])
    stretch = world.stores["locomotion.creatures"].release_stretch[0]
    assert stretch == 0.04  # the scene default
    anchor = world.suckers.anchor[row].copy()
    # just within the stretch: held (straight up, so the reach is unchanged)
    world.suckers.anchor[row] = sucker_points(world)[row] + np.array([0.0, 0.0, 0.9 * stretch])
    world.step(1)
    assert world.suckers.attached[row]
    world.suckers.anchor[row] = anchor + np.array([0.0, 0.0, 0.1])
    world.step(1)
    assert not world.suckers.attached[row]
    assert events.reasons() == ["stretch"]
    assert world.events.counts["sucker_released"] == 1


def test_release_on_reach(make_world: Callable[..., World]) -> None:
    # stretch cannot trip first: the anchor may be pulled up to 10 m away
    world = _world(make_world, locomotion={"release_stretch": 10})
    events = Recorder(world)
    _grab(world, 0)
    t = world.tentacles
    row = int(t.tip_sucker[0])
    reach = world.stores["locomotion.creatures"].release_reach[0] * t.length[0]
    assert_allclose(reach, 1.1 * 0.07 * np.linspace(1.0, 0.3, 10).sum(), rtol=1e-12)

    def place(fraction: float) -> None:
        base = world.transforms.pos[t.base_row[0]]
        out = world.suckers.anchor[row, :2] - base[:2]
        out /= np.linalg.norm(out)
        world.suckers.anchor[row, :2] = base[:2] + fraction * reach * out

    place(0.99)
    world.step(1)
    assert world.suckers.attached[row]
    place(1.01)
    world.step(1)
    assert not world.suckers.attached[row]
    assert events.reasons() == ["reach"]
    assert world.events.counts["sucker_released"] == 1


def test_each_release_is_counted(make_world: Callable[..., World]) -> None:
    world = _world(make_world)
    events = Recorder(world)
    row = int(world.tentacles.tip_sucker[0])
    _grab(world, 0)
    world.suckers.anchor[row] += np.array([0.0, 0.0, 0.1])
    world.step(1)  # stretch; the tentacle still attaches, so it grabs again
    _grab(world, 0)
    _hold(world, 0, Kind.DETACH)
    world.step(1)
    assert events.reasons() == ["stretch", "command"]
    assert world.events.counts["sucker_attached"] == 2
    assert world.events.counts["sucker_released"] == 2


def _crowd(count: int) -> dict[str, Any]:
    """`count` small creatures on a grid, each crawling 1.5 m along +x; few full and
    reduced slots, so most are replayed (KINEMATIC) after 0.1 s."""
    creatures = []
    for i in range(count):
        x, y = 2.0 * (i % 4), 2.0 * (i // 4)
        creatures.append(
            {
                "name": f"c{i}",
                "position": [x, y],
                "tentacles": {"count": 4, "links": 5},
                "goals": [{"position": [x + 1.5, y]}],
            }
        )
    lod = {"full": 1, "reduced": 1, "hold_seconds": 0.1}
    return {"version": 1, "physics": {"lod": lod}, "creatures": creatures}


def test_replayed_creatures_hold_no_sucker_and_a_promoted_one_starts_free(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_crowd(8))
    creature_of_sucker = world.tentacles.creature_row[world.suckers.tentacle_row]
    replayed_before = np.zeros(len(world.creatures), dtype=bool)
    held_by_replayed = 0
    for _ in range(150):
        world.step(1)
        replayed = world.physics.kinematic_creatures(len(world.creatures))
        steady = replayed & replayed_before  # replayed since the last frame's decisions
        held_by_replayed += int(world.suckers.attached[steady[creature_of_sucker]].sum())
        replayed_before = replayed
    assert replayed.sum() >= 4  # most of the crowd is replayed
    assert held_by_replayed == 0
    # a promoted creature starts free: no anchor left behind pulls it
    row = int(np.flatnonzero(replayed)[0])
    world.lod.promote(int(world.creatures.entity[row]))
    world.step(1)
    assert not world.physics.kinematic_creatures(len(world.creatures))[row]
    assert not world.suckers.attached[creature_of_sucker == row].any()


def test_a_crowd_lets_go_for_the_same_reasons_with_and_without_the_kernel(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.locomotion.systems import suckers

    assert suckers.KERNELS.get() is not None  # numba comes with the dev extra
    runs = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(suckers.KERNELS, "backend", backend)
        world = make_world(crowd_scene(8, seed=1))
        recorder = Recorder(world)
        for frame in range(150):
            world.step(1)
            gaits = world.stores["locomotion.creatures"]
            if frame == 90:  # every held sucker stretched too far
                gaits.release_stretch[:], stretch = 0.0, gaits.release_stretch.copy()
            if frame == 91:
                gaits.release_stretch[:] = stretch
            if frame == 120:  # every tentacle base too far from its anchor
                gaits.release_reach[:] = 0.01
        events = [
            (name, frame, p["sucker"], p.get("reason"), tuple(p.get("anchor", ())))
            for name, frame, p in recorder.events
        ]
        runs.append((world.transforms.pos.copy(), events))
    assert_array_equal(runs[0][0], runs[1][0])
    assert runs[0][1] == runs[1][1]  # the same suckers, frames and reasons, in order
    reasons = {reason for name, _, _, reason, _ in runs[0][1] if name == "sucker_released"}
    assert reasons == {"command", "stretch", "reach"}


def test_a_sucker_stretched_exactly_to_its_limit_holds_with_and_without_the_kernel(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Limits set to suckers' own stretches: the kernel must find every stretch to the
    bit for the same suckers to let go."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.locomotion.systems import suckers

    world = make_world(crowd_scene(8, seed=1))
    world.step(60)
    system = next(s for s in world.schedule if isinstance(s, suckers.Suckers))
    gaits = world.stores["locomotion.creatures"]
    held = np.flatnonzero(world.suckers.attached)
    stretch = np.linalg.norm(sucker_points(world, held) - world.suckers.anchor[held], axis=1)
    creature = world.tentacles.creature_row[world.suckers.tentacle_row[held]]
    assert len(np.unique(creature)) >= 3
    gaits.release_reach[:] = 1e9
    for at, c in enumerate(np.unique(creature)):  # the least stretched sucker sits exactly
        limit = stretch[creature == c].min()  # on the limit (holds) or one ulp past it
        gaits.release_stretch[c] = limit if at % 2 else np.nextafter(limit, -np.inf)
    start = world.snapshot()
    released = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(suckers.KERNELS, "backend", backend)
        world.restore(start)
        recorder = Recorder(world)
        system.process(world, world.settings.dt)
        released.append([(p["sucker"], p["reason"]) for _, _, p in recorder.events])
    assert released[0] == released[1]
    let_go = {sucker for sucker, _ in released[0]}
    assert "stretch" in {reason for _, reason in released[0]}
    assert len(let_go) < len(held)  # those exactly on their limit hold
