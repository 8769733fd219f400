"""The render plugin: the sandbox's renderer gets each frame's poses (`play` adds it).

Systems: render (stage output). Other plugins draw, add HUD sections and take clicks
through the render layer's registries (`Spheres`, `Lines`, `Draws`, `FramedPoints`,
`Panels`, `Clicks`, `UndoStates`: `ecs_tentacles.render.registries`), which the
renderer, HUD and sandbox call; none of them names a feature. Its own spheres: each
creature's physics tier while the renderer's `show_tiers` is on (`render.tiers`; a
debugging aid, not in the clean view).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.render.registries import Marker, OverlaySpheres
from ecs_tentacles.render.tiers import tier_markers
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.render.renderer import Renderer


class RenderPlugin(Plugin):
    name = "render"
    description = "hands the newest body poses to the sandbox renderer"

    def __init__(
        self, config: dict[str, object] | None = None, *, renderer: Renderer | None = None
    ):
        super().__init__(config)
        if renderer is None:
            raise ValueError("the render plugin needs the sandbox's renderer (renderer=...)")
        self.renderer = renderer

    def systems(self) -> list[System]:
        from ecs_tentacles.render.systems.render import RenderSync

        return [RenderSync(self.renderer)]

    def build(self, app: App) -> None:
        """Its drawing, HUD sections and clicks (`ecs_tentacles.render.registries`)."""
        app.add(OverlaySpheres, self._spheres)

    def _spheres(self, world: Host) -> list[Marker]:
        return tier_markers(self.renderer) if self.renderer.show_tiers else []
