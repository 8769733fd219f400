"""One shard's bake, as a Ray worker (or this process) runs it.

`bake_shard(plan, members)` builds only the creatures `members` (scene indices) of
the plan's scene and bakes them exactly as a local bake would (same seed, rates and
scene in the header and for everything scene-wide, such as the fur's shared point
count and the threats; each creature draws its own random values, see
`ecs_tentacles.creatures.body.creature_rng`), recording each creature's contact sphere every
frame (`ecs_tentacles.distributed.spheres`). Physics steps on one thread: a worker
is one CPU.

Test hook: when `ECS_TENTACLES_CRASH_DIR` names a folder holding a file named after
the shard's key, the worker claims that file (a rename, so only one worker does) and
dies at once with `os._exit`, as a killed worker would; tests use it to show that
Ray's retry bakes the shard again and the merged take is unchanged.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ecs_tentacles.distributed.spheres import ContactSpheres
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.take import Take

CRASH_DIR = "ECS_TENTACLES_CRASH_DIR"


@dataclass
class ShardResult:
    """A shard's take, its creatures' contact spheres and how long the bake took."""

    members: list[int]
    take: Take
    spheres: np.ndarray  # (steps + 1, creatures, 4)
    seconds: float = 0.0
    cpu_seconds: float = 0.0  # of the worker process during the task


def bake_shard(
    plan: BakePlan,
    members: list[int],
    key: str = "",
    options: WorldOptions | None = None,
    *,
    on_steps: Callable[[int], None] | None = None,
) -> ShardResult:
    """Bake creatures `members` of `plan`'s scene with `options` (the code it may import),
    on one thread; `key` names the shard (test hook)."""
    _crash_if_asked(key)
    started, cpu = time.perf_counter(), time.process_time()
    spheres = ContactSpheres(plan.steps)
    take = bake(
        plan,
        (options or WorldOptions()).but(threads=1, only=frozenset(members)),
        progress=False,
        on_world=lambda world: world.add_systems(spheres),
        on_steps=on_steps,
    )
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu
    return ShardResult(list(members), take, spheres.spheres, wall, cpu)


def _crash_if_asked(key: str) -> None:
    folder = os.environ.get(CRASH_DIR)
    if not folder or not key:
        return
    request = os.path.join(folder, key)
    try:
        os.rename(request, f"{request}.claimed.{os.getpid()}")
    except OSError:
        return  # no request for this shard (or another worker claimed it)
    os._exit(70)
