"""A small crowd whose creatures replay gait clips: the case version 2 takes are for."""

from __future__ import annotations

from pathlib import Path

import pytest

from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.take import Take
from tests.conftest import uniform_crowd


def replay_crowd(path: Path, count: int = 6) -> Path:
    """`count` creatures of one plan crawling across, at most one at full physics, the
    rest replaying gait clips (level of detail), written to `path`."""
    return uniform_crowd(path, count, {"full": 1, "reduced": 0, "hold_seconds": 0}, "--seed", "1")


@pytest.fixture(scope="session")
def crowd_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return replay_crowd(tmp_path_factory.mktemp("crowd") / "crowd6.json")


@pytest.fixture(scope="session")
def crowd_plan(crowd_scene: Path) -> BakePlan:
    return BakePlan.make(crowd_scene, seconds=1.0, fps=24)


@pytest.fixture(scope="session")
def crowd_take(crowd_plan: BakePlan) -> Take:
    """The crowd baked in memory: every body's pose as the world showed it."""
    return bake(crowd_plan, progress=False)
