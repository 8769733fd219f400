"""render: hands the newest body poses to the sandbox renderer.

Reads: Transform store (pos, quat). Writes: the Renderer's last two pose snapshots,
between which it interpolates when it draws at display rate. The render plugin
(`ecs_tentacles.render.plugin`) adds it, in the sandbox (`ecs-tentacles play`) only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.render.renderer import Renderer
    from ecs_tentacles.roster_change import RosterChange


class RenderSync(System):
    name = "render"
    calls_hooks = True  # the plugins' drawing entries
    stage = "output"
    reads = ("transforms.pos", "transforms.quat")

    def __init__(self, renderer: Renderer):
        self.renderer = renderer

    def setup(self, world: Host) -> None:
        self.renderer.sync()

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        self.renderer.roster_changed(change)

    def process(self, world: Host, dt: float) -> None:
        self.renderer.sync()
