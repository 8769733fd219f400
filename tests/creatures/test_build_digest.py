"""A crowd is built the same as it always was: entity for entity, component for
component, store row for store row, physics state bit for bit (`world_digest`).

The digests were recorded on the build that added creatures one row at a time
(main at 7759b2c); a faster build must give the same world. Like the take hashes they
are compared only under the MuJoCo and numpy versions they were recorded with.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.world import World
from tests.creatures.world_digest import digest, world_parts

VERSIONS = {"mujoco": "4.0.1", "numpy": "2.4.6"}
RECORDED = {
    "varied": "469bd13b892a4ad592a068c251cee9776de3d4a23e685160045c6a5873c329d0",
    "uniform": "deef08ae3a8d42e27c08bc4896d0e96ab783a6bf18e97080ab48b9db3c3c620a",
    "asymmetric": "9c70095f24cf490527d65bff30d05684a8fd28e1ea2b5fd9d1e097fe7e4cd14c",
}


def scene(name: str) -> Any:
    if name == "varied":  # four body plans, fur on some, behaviour varied
        return crowd_scene(12, 5, None, idle=0.25, species=4, uniform=False)
    if name == "uniform":
        return crowd_scene(9, 2, None, uniform=True)
    return name  # a bundled scene: overrides, twist


@pytest.mark.skipif(
    {"mujoco": mujoco.__version__, "numpy": np.__version__} != VERSIONS,
    reason=f"digests recorded with {VERSIONS}",
)
@pytest.mark.parametrize("name", sorted(RECORDED))
def test_built_world_is_the_one_recorded(name: str) -> None:
    world = World.from_scene(scene(name), threads=1)
    try:
        assert digest(world_parts(world)) == RECORDED[name]
    finally:
        world.close()
