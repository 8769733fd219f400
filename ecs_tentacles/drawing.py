"""What plugins hand the sandbox, and what it hands them: the data of the render hooks.

The generic renderer, HUD and mouse handling (`ecs_tentacles.render`) name no feature;
each frame they ask every plugin (`ecs_tentacles.plugin.Plugin`):

- `render_spheres(world)` -> `plugin.Marker`s: instanced spheres (suckers, threats);
- `render_lines(world, view)` -> line-list vertices (2n, 7: xyz rgba), joined into the
  renderer's one line batch (goal rings and paths, fur control markers);
- `render_draw(world, view)` -> draw calls: anything else, drawn with the plugin's own
  GL objects, made lazily inside the hook and kept in `view.state` (fur's ribbons);
- `render_points(world)` -> points (n, 3) "frame all" keeps in view (goals);
- `sandbox_panels(sandbox)` -> `Panel`s: HUD sections, their windows and mouse grabs;
- `sandbox_click(world, click)`: a click in the 3D view (`Click`; goals are set so).

This module is pure data (numpy only, no GL): importing a plugin stays cheap and
headless worlds never load pyglet.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

LINE_FLOATS = 7  # a line vertex: x, y, z, r, g, b, a


@dataclass
class RenderView:
    """The frame being drawn, as the renderer hands it to `render_lines` / `render_draw`.

    `pos`, `quat`: body poses (rows of the Transform store) interpolated between the last
    two physics frames; `creatures`: the creature entities drawn, `colours` each one's
    rgb; `eye`, `view_projection` (4 x 4, column vectors), `light` (unit, towards it),
    `pixel` (metres one pixel spans at the camera's target): the camera; `overlays`:
    editing aids (the fur controls' markers) are wanted (the sandbox's HUD is showing);
    `state`: objects plugins keep for as long as the renderer lives, across worlds
    (their GL buffers and display settings), by a key starting with the plugin's name;
    `selected`: the creature the sandbox has selected (None: none), the last picked of
    `selection` (every selected creature).
    """

    pos: np.ndarray
    quat: np.ndarray
    creatures: list[int] = field(default_factory=list)
    colours: dict[int, np.ndarray] = field(default_factory=dict)
    eye: np.ndarray = field(default_factory=lambda: np.zeros(3))
    view_projection: np.ndarray = field(default_factory=lambda: np.eye(4))
    light: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    pixel: float = 0.0
    overlays: bool = False
    state: dict[str, Any] = field(default_factory=dict)
    selected: int | None = None  # the sandbox's selected creature (an entity), if any
    selection: tuple[int, ...] = ()  # every selected creature


@dataclass(frozen=True)
class Click:
    """A click in the sandbox's 3D view (not on the HUD), offered to `sandbox_click`.

    `button`: "left", "right" or "middle"; `shift`: held; `ground`: where the ray under
    the pointer meets the ground plane (world metres, (3,)), None above the horizon;
    `creature`: the creature under the pointer (the sandbox selects it on a left click
    before plugins see it), None if none; `selected`: the selected creature (the last
    picked); `selection`: every selected creature (the sandbox may select many);
    `ctrl`: held.
    """

    button: str
    shift: bool
    ground: np.ndarray | None
    creature: int | None
    selected: int | None
    selection: tuple[int, ...] = ()
    ctrl: bool = False

    @property
    def chosen(self) -> tuple[int, ...]:
        """The creatures a click acts on: the selection, else the selected one."""
        if self.selection:
            return self.selection
        return () if self.selected is None else (self.selected,)


class Panel:
    """A section of the sandbox's HUD that a plugin adds (`Plugin.sandbox_panels`).

    `title` heads the section; `draw(gui)` builds its widgets (Dear ImGui through
    `ecs_tentacles.render.gui.Gui`). Sections are ordered by `order` (the sandbox's own
    Stats, Physics and Plugins are 0; ties keep plugin order) and start folded when
    `closed`. A panel lives as long as the sandbox: `attach` tells it the world was
    rebuilt or reset, `select` that the selection changed. It may draw more ImGui
    windows (`windows`) and take the mouse: `press` at a pixel of the 3D view returns
    True to grab it, then `drag` and `release` follow; `key` sees keys before the
    sandbox does.
    """

    title: str = ""
    order: int = 10
    closed: bool = False

    def draw(self, gui: Any) -> None:
        """The section's widgets (called while it is open)."""

    def windows(self, gui: Any) -> None:
        """More ImGui windows beside the panel (the fur timeline), every frame."""

    def attach(self, world: Any) -> None:
        """The sandbox draws `world` from now on (rebuilt or reset)."""

    def select(self, creature: int | None, tentacle: int | None) -> None:
        """The sandbox selected `creature` (and tentacle index `tentacle`, None: all)."""

    def key(self, symbol: int, modifiers: int) -> bool:
        """A key went down (pyglet's symbol and modifiers) while the 3D view has the
        keyboard; True: handled (the sandbox does nothing more with it)."""
        return False

    def press(self, x: float, y: float) -> bool:
        """A left press at pyglet pixel (x, y) of the 3D view; True takes the drag."""
        return False

    def drag(self, x: float, y: float) -> None:
        """The pointer moved while this panel holds the mouse."""

    def release(self) -> None:
        """The mouse button went up."""


def line_segments(polyline: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """Line-list vertices (2(n-1), 7) for a polyline (n, 3) in one rgba colour."""
    starts, ends = polyline[:-1], polyline[1:]
    pairs = np.empty((2 * len(starts), 3))
    pairs[0::2], pairs[1::2] = starts, ends
    return np.hstack([pairs, np.tile(colour, (len(pairs), 1))])


RING_SEGMENTS = 48
_ANGLES = np.linspace(0, 2 * np.pi, RING_SEGMENTS + 1)
CIRCLE = np.stack([np.cos(_ANGLES), np.sin(_ANGLES), np.zeros_like(_ANGLES)], axis=1)
"""A unit circle in the ground plane, (RING_SEGMENTS + 1, 3): scale and move it for rings."""


class HasSurface(Protocol):
    """What `draped` needs of a ground: the topmost surface under points (`Ground`)."""

    def surface(self, xy: np.ndarray) -> np.ndarray: ...


def draped(points: np.ndarray, ground: HasSurface, lift: float) -> np.ndarray:
    """`points` (n, 3) put on the topmost surface under them (the ground, or a solid: a
    ramp, a platform), `lift` m above it: a ring round a goal or a creature on a hillside
    or a ledge follows it instead of sinking into it."""
    out = np.array(points, dtype=np.float64)
    out[:, 2] = ground.surface(out[:, :2]) + lift
    return out
