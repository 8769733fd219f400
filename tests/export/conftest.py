"""Shared pieces of the export tests: a small scene, synthetic fur guides, a recorded take."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.fur.outputs import GUIDES
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.take import Take
from ecs_tentacles.take.registries import CurvesFrame, TrackSource
from ecs_tentacles.world import World
from tests.conftest import once_a_session, uniform_crowd

# One creature, three tentacles of four links, tip suckers, a goal 1 m ahead.
SMALL_SCENE: dict[str, Any] = {
    "version": 1,
    "name": "small",
    "seed": 4,
    "creatures": [
        {
            "name": "octo",
            "position": [0, 0],
            "tentacles": {"count": 3, "links": 4},
            "goals": [{"position": [1.0, 0.0], "radius": 0.2}],
        }
    ],
}


def three_by_three(name: str, x: float) -> dict[str, Any]:
    """A scene's creature entry: `name` at (x, 0), three tentacles of three links."""
    return {"name": name, "position": [x, 0.0], "tentacles": {"count": 3, "links": 3}}


def come_and_go_take() -> Take:
    """12 frames of creatures `a` and `b` (`three_by_three`, 3 m apart): `b` despawned
    after frame 4, `late` spawned 6 m along after frame 6."""
    creature = three_by_three
    scene = {"version": 1, "creatures": [creature("a", 0.0), creature("b", 3.0)]}
    with World.from_scene(scene) as world:
        recorder = world.add_system(Record())
        world.step(4)
        world.despawn(world.creature("b"))
        world.step(2)
        world.spawn(creature("late", 6.0))
        world.step(5)
        return recorder.take()


def link_centres(world: World) -> CurvesFrame:
    """Synthetic fur: one guide per tentacle through its link centres (moves with it)."""
    points, widths, owners = [], [], []
    for entity, creature in world.query(Creature):
        for tentacle_entity in creature.tentacles:
            links = world.component(tentacle_entity, Tentacle).links
            points.append([world.component(e, Transform).pos for e in links])
            widths.append([2 * world.component(e, Link).radius for e in links])
            owners.append(entity)
    return CurvesFrame(np.array(points), np.array(widths), np.array(owners))


LINK_CENTRES = TrackSource(GUIDES, link_centres)  # in place of the fur plugin's guides


def record(
    scene: dict[str, Any], frames: int, every: int = 1, **recorder: Any
) -> tuple[World, Record]:
    """A world of `scene` with a Record system, stepped `frames` frames (caller closes it)."""
    world = World.from_scene(scene)
    system = Record(every, **recorder)
    world.add_system(system)
    world.step(frames)
    return world, system


@pytest.fixture(scope="session")
def guided_take() -> Iterator[Take]:
    """0.2 s of the small scene at 30 fps (every 2nd frame of 60), with synthetic guides."""
    world, system = record(SMALL_SCENE, 12, every=2, tracks=[LINK_CENTRES])
    yield system.take()
    world.close()


@pytest.fixture(scope="session")
def gltf_validator() -> tuple[str, Path]:
    """(node, the npm package gltf-validator): $ECS_TENTACLES_GLTF_VALIDATOR, else where
    .ci/run installs it (<venv>/node/node_modules/gltf-validator); skips with the reason."""
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not on PATH, so the Khronos glTF validator (npm) cannot run")
    default = Path(sys.prefix) / "node" / "node_modules" / "gltf-validator"
    package = Path(os.environ.get("ECS_TENTACLES_GLTF_VALIDATOR", default))
    if not (package / "package.json").is_file():
        pytest.skip(
            f"the npm package gltf-validator is not at {package}: `npm install --prefix"
            f" {Path(sys.prefix) / 'node'} gltf-validator` (.ci/run does) or set"
            " ECS_TENTACLES_GLTF_VALIDATOR"
        )
    return node, package


def khronos_report(path: Path, validator: tuple[str, Path]) -> dict[str, Any]:
    """The Khronos glTF validator's JSON report on `path` (it must run and exit 0)."""
    node, package = validator
    tool = Path(__file__).resolve().parents[2] / "tools" / "validate_gltf.cjs"
    result = subprocess.run(
        [node, str(tool), str(path), str(package)],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    report: dict[str, Any] = json.loads(result.stdout)
    return report


def replay_crowd_take(folder: Path, seconds: float = 2.0) -> Path:
    """16 uniform creatures, `seconds` at 24 fps, level of detail on with room for one at
    full physics and one reduced: the others replay the crawl clip from frame 1 (a take
    of version 2 records them as clip, phase and root motion). The take's path."""
    lod = {"full": 1, "reduced": 1, "hold_seconds": 0}
    scene = uniform_crowd(folder / "crowd16.json", 16, lod, "--seed", "1")
    take = folder / "crowd16.npz"
    argv = ["bake", str(scene), "--seconds", str(seconds), "--fps", "24", "--out", str(take)]
    assert main([*argv, "--quiet"]) == 0
    return take


@pytest.fixture(scope="session")
def replay_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A take (version 2) of 16 creatures, 15 of them replaying a gait clip from frame 1
    (`replay_crowd_take`), baked once a session for all workers."""
    return once_a_session(tmp_path_factory, "replayed", replay_crowd_take)


def switching_crowd_take(folder: Path) -> Path:
    """9 uniform creatures packed 1.3 m apart, 4 s at 24 fps, level of detail on with room
    for one at full physics and one reduced: crawling inwards they come near each other
    and go physical, then apart and replay again, so some leave their clip and come back
    (creature 8: replayed on frames 34-38, 56-57 and 82-96; seed 11, since the reduced
    tier's rate went from a quarter to an eighth of the scene's: seed 2's creatures no
    longer come back twice). The take's path."""
    lod = {"full": 1, "reduced": 1, "hold_seconds": 0}
    scene = uniform_crowd(folder / "switching9.json", 9, lod, "--seed", "11", "--spacing", "1.3")
    take = folder / "switching9.npz"
    argv = ["bake", str(scene), "--seconds", "4", "--fps", "24", "--out", str(take)]
    assert main([*argv, "--quiet"]) == 0
    return take


@pytest.fixture(scope="session")
def switching_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A take (version 2) of 9 creatures that switch between physics and a gait clip,
    several of them more than once (`switching_crowd_take`), baked once a session."""
    return once_a_session(tmp_path_factory, "switching", switching_crowd_take)
