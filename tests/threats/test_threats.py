"""The threats system: path threats follow their keyframed paths, frame by frame."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numpy.testing import assert_allclose

from ecs_tentacles.threats.data import Threat, ThreatData, build_threats
from ecs_tentacles.world import World

TENTACLES = {"count": 3, "links": 2}


def scene(*threats: dict[str, Any]) -> dict[str, Any]:
    return {"version": 1, "creatures": [{"tentacles": TENTACLES}], "threats": list(threats)}


def key(time: float, x: float, easing: str = "linear") -> dict[str, Any]:
    return {"time": time, "position": [x, 1.0, 0.1], "easing": easing}


def test_a_path_threat_follows_its_keys_over_the_frames(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene({"path": [key(0, 0.0), key(1, 2.0), key(2, 2.0)]}))
    store = world.resource(ThreatData).store
    seen = []
    for _ in range(91):  # the system evaluates at the frame's time, frame / fps
        world.step(1)
        seen.append(store.pos[0].copy())
    for frame in (0, 15, 30, 60, 90):
        x = min(2.0, 2.0 * frame / 60)
        assert_allclose(seen[frame], [x, 1.0, 0.1], atol=1e-12)


def test_threats_move_with_fur_off(make_world: Callable[..., World]) -> None:
    """No emotion reads them, yet they follow their paths (the sandbox draws them)."""
    world = make_world(scene({"path": [key(0, 0.0), key(1, 2.0)]}), plugins={"fur": False})
    world.step(31)
    assert_allclose(world.resource(ThreatData).store.pos[0], [1.0, 1.0, 0.1])


def test_easing_and_holding_after_the_last_key(make_world: Callable[..., World]) -> None:
    world = make_world(
        scene(
            {"name": "jumper", "path": [key(0, 0.0, "step"), key(0.5, 3.0)]},
            {"name": "eased", "path": [key(0, 0.0, "ease"), key(1, 1.0)]},
        )
    )
    world.step(16)  # t = 0.25 s at the last frame
    positions = world.resource(ThreatData).positions(world)
    assert_allclose(positions["jumper"], [0.0, 1.0, 0.1])  # step: holds until its next key
    assert_allclose(positions["eased"][0], 0.15625)  # smoothstep(0.25)
    world.step(60)  # t = 1.25 s: both past their last keys
    positions = world.resource(ThreatData).positions(world)
    assert_allclose(positions["jumper"], [3.0, 1.0, 0.1])
    assert_allclose(positions["eased"], [1.0, 1.0, 0.1])


def test_a_threat_added_at_run_time_starts_moving(make_world: Callable[..., World]) -> None:
    world = make_world(scene({"path": [key(0, 0.0)]}))
    world.step(2)
    (late,) = build_threats(world, [{"name": "late", "path": [key(0, 5.0), key(1, 6.0)]}])
    assert world.component(late, Threat).pos[0] == 5.0  # placed at its first key
    world.step(1)  # frame 2: t = 2 / 60 s
    assert_allclose(world.component(late, Threat).pos, [5.0 + 2.0 / 60.0, 1.0, 0.1])
    assert len(world.resource(ThreatData)) == 2
