"""Loading a scene leaves Python's garbage collector as it found it, built or refused."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

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
