"""The sucker API: where suckers are, attach one, release one.

    from ecs_tentacles.locomotion.grip import attach, release, sucker_points

    attach(world, sucker_entity)             # fires sucker_attached (anchor: where it is now)
    release(world, sucker_entity, "script")  # fires sucker_released (with the reason)

The suckers plugin's system (`ecs_tentacles.locomotion.systems.suckers`) grips with
these; a script may call them whether the plugin is on or not (the sucker bodies and
their MuJoCo constraints are core).

Reads: Sucker store (link_row, offset), Transform store. Writes: Sucker store
(attached, anchor).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Sucker
from ecs_tentacles.events import SuckerReleased
from ecs_tentacles.locomotion.events import SuckerAttached
from ecs_tentacles.numeric.quaternions import quat_rotate

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def sucker_points(world: Host, rows: np.ndarray | None = None) -> np.ndarray:
    """World position (n, 3) of every sucker (or of sucker `rows`), by sucker row."""
    suckers, transforms = world.suckers, world.transforms
    links = suckers.link_row if rows is None else suckers.link_row[rows]
    offset = suckers.offset if rows is None else suckers.offset[rows]
    points: np.ndarray = transforms.pos[links] + quat_rotate(transforms.quat[links], offset)
    return points


def attach(world: Host, sucker_entity: int) -> None:
    """Fix a sucker to the world where it is now; fires `sucker_attached`."""
    sucker = world.component(sucker_entity, Sucker)
    if sucker.attached:
        return
    sucker.anchor = sucker_points(world, np.array([sucker.row]))[0]
    sucker.attached = True
    world.events.emit(SuckerAttached(world, sucker_entity, sucker.anchor.copy()))


def release(world: Host, sucker_entity: int, reason: str = "command") -> None:
    """Let a sucker go; fires `sucker_released` with the `reason`."""
    sucker = world.component(sucker_entity, Sucker)
    if not sucker.attached:
        return
    sucker.attached = False
    world.events.emit(SuckerReleased(world, sucker_entity, reason))
