"""The physics systems write only what they declare, and declare real columns.

Each physics system runs with only the columns it declares (`tests/declarations.py`:
others unreadable, those it does not write read-only), through contact and a blow-up
and its recovery, so an undeclared read or write fails.
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ecs_tentacles.physics
from ecs_tentacles.physics.frame_systems import physics_systems
from ecs_tentacles.physics.host import PhysicsHost
from ecs_tentacles.world import World
from tests.declarations import declared_only, step_declared

OFF = {"locomotion": False, "suckers": False, "threats": False, "fur": False, "clips": False}
SCENE: dict[str, Any] = {
    "version": 1,
    "creatures": [
        {"name": f"c{i}", "position": [0.7 * i, 0.0], "tentacles": {"count": 3, "links": 5}}
        for i in range(2)  # close enough to touch: contact proxies run
    ],
}


def _columns(world: World) -> set[str]:
    return {f"{name}.{f.name}" for name, store in world.stores.items() for f in store.fields()}


def test_declared_reads_and_writes_name_real_columns(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE, plugins=OFF)
    known = _columns(world) | {"physics"}
    for system in physics_systems():
        assert set(system.reads) <= known, system.name
        assert set(system.writes) <= known, system.name


def test_the_physics_writes_no_column_it_does_not_declare(
    make_world: Callable[..., World],
) -> None:
    world = make_world(SCENE, plugins=OFF)
    assert {system.name for system in world.schedule} == {
        "physics", "physics_sync", "physics_health"
    }  # fmt: skip
    step_declared(world, 30)  # each system with only its declared columns (tests/declarations)
    assert world.physics.proxies.in_use  # the creatures are near each other
    world.physics.views[1].data.qvel[7] = np.nan
    step_declared(world, 5)
    assert world.physics.health.recoveries == 1
    with (
        declared_only(world, world.schedule["physics"]),
        pytest.raises(ValueError, match="read-only"),
    ):
        world.motors.target[0, 0] = 1.0  # what the check relies on


def test_no_physics_module_imports_the_world() -> None:
    """Type-only imports included: the physics sees a world as `PhysicsHost`."""
    folder = Path(ecs_tentacles.physics.__file__).parent
    for path in sorted(folder.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            else:
                continue
            assert "ecs_tentacles.world" not in names, path.name


def test_a_world_has_everything_the_physics_asks_of_it(
    make_world: Callable[..., World],
) -> None:
    world = make_world(SCENE, plugins=OFF)
    wanted = [n for n in vars(PhysicsHost) if not n.startswith("_")]
    assert {"settings", "transforms", "suckers", "component"} <= set(wanted)
    for name in wanted:
        assert hasattr(world, name), name
