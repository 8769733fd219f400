"""Loading a scene leaves Python's garbage collector as it found it, built or refused;
a crowd's objects frozen while its world lives."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.creatures import loading
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World


@pytest.fixture
def collector() -> Iterator[None]:
    was = gc.isenabled()
    yield
    (gc.enable if was else gc.disable)()


def test_the_collector_is_back_on_after_a_build_and_after_a_refusal(collector: None) -> None:
    gc.enable()
    with World.from_scene("octopus", threads=1):
        assert gc.isenabled()
    with pytest.raises(SceneError):
        World.from_scene({"version": 1, "creatures": [{"tentacles": {"count": 0}}]})
    assert gc.isenabled()


def test_a_collector_switched_off_stays_off(collector: None) -> None:
    gc.disable()
    with World.from_scene("octopus", threads=1):
        assert not gc.isenabled()


def test_a_crowds_objects_are_frozen_until_it_closes(
    collector: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A crowd's build leaves its objects out of the collector's walks (`gc.freeze`)
    while the world lives; closed, they are the collector's again. A smaller world
    freezes nothing."""
    gc.enable()
    assert gc.get_freeze_count() == 0
    with World.from_scene("octopus", threads=1):  # one creature: not a crowd
        assert gc.get_freeze_count() == 0
    monkeypatch.setattr(loading, "FROZEN_CROWD", 2)
    world = World.from_scene(crowd_scene(2, 0, None, uniform=True), threads=1)
    try:
        assert gc.isenabled()
        frozen = gc.get_freeze_count()
        assert frozen > 0
        world.step(2)  # a frame's new objects are the collector's as usual
        assert gc.get_freeze_count() <= frozen
    finally:
        world.close()
    assert gc.get_freeze_count() == 0
