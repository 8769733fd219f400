"""What the renderer and the sandbox call, and what they hand the plugins: the render
layer's registries (`ecs_tentacles.registry`) and their data.

The generic renderer, HUD and mouse handling (`ecs_tentacles.render`) name no feature;
plugins add entries in `build(app)` (`app.add(Spheres, entry)`), and the layer calls
every entry, in plugin order:

- `Spheres`: `entry(world)` -> `Marker`s: instanced spheres (threats, a game's markers);
- `Lines`: `entry(world, view)` -> a list of line-list vertex arrays (2n, 7: xyz rgba),
  joined into the renderer's one line batch (a game's pen and reach rings, fur control
  markers, which draw only while `view.overlays`);
- `OverlaySpheres`, `OverlayLines`: the same, for the editor's aids (attached suckers,
  physics tiers; goal rings and paths): drawn except in the clean view (`view.clean`:
  a game, `play --clean`, a video), as the selection rings are;
- `Draws`: `entry(world, view)` -> draw calls made: anything else, drawn with the
  plugin's own GL objects, made lazily inside the entry and kept in `view.state`
  (fur's ribbons);
- `FramedPoints`: `entry(world)` -> points (n, 3) that "frame all" keeps in view, or
  None (goals);
- `Panels`: `entry(sandbox)` -> `Panel`s: HUD sections, their windows (a panel's with
  `overlay_windows` set, the fur timeline, not in the clean view) and mouse grabs,
  made once per sandbox and kept across rebuilds and resets; `sandbox` is a
  `SandboxView`, what a panel may use of the sandbox;
- `Clicks`: `entry(world, click)` -> True when it took the click in the 3D view
  (`Click`; goals are set so); the first to take it ends the offer;
- `UndoStates`: (`capture(world)`, `restore(world, state)`): what the sandbox's undo
  keeps of a plugin's directable state (each creature's goals, the locomotion sliders).

This module is pure data (numpy only, no GL): importing it keeps a headless world free
of pyglet.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from pyglet.window import BaseWindow
    from pyglet.window.key import KeyStateHandler

    from ecs_tentacles.host import Host
    from ecs_tentacles.render.camera import OrbitCamera
    from ecs_tentacles.render.gui import Gui
    from ecs_tentacles.render.selection import Selection
    from ecs_tentacles.world import World

LINE_FLOATS = 7  # a line vertex: x, y, z, r, g, b, a


@dataclass(frozen=True)
class Marker:
    """Spheres a plugin asks the renderer to draw: centres (n, 3), size (x, y, z), rgba."""

    positions: object
    size: tuple[float, float, float]
    rgba: tuple[float, float, float, float]


@dataclass
class RenderView:
    """The frame being drawn, as the renderer hands it to the `Lines` and `Draws` entries.

    `pos`, `quat`: body poses (rows of the Transform store) interpolated between the last
    two physics frames; `creatures`: the creature entities drawn, `colours` each one's
    rgb; `eye`, `view_projection` (4 x 4, column vectors), `light` (unit, towards it),
    `pixel` (metres one pixel spans at the camera's target), `per_metre` (what one
    pixel spans 1 m from the eye, so `per_metre * distance` at any distance; 0: not
    known): the camera; `overlays`:
    editing aids (the fur controls' markers) are wanted (the sandbox's HUD is showing,
    not the clean view); `clean`: the clean view, a picture for showing (a game, `play
    --clean`, a video): the editor's aids are not drawn (`OverlaySpheres`, `OverlayLines`,
    the selection rings; `overlays` is False);
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
    per_metre: float = 0.0
    overlays: bool = False
    clean: bool = False
    state: dict[str, object] = field(default_factory=dict)
    selected: int | None = None  # the sandbox's selected creature (an entity), if any
    selection: tuple[int, ...] = ()  # every selected creature


@dataclass(frozen=True)
class Click:
    """A click in the sandbox's 3D view (not on the HUD), offered to the `Clicks` entries.

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
    """A section of the sandbox's HUD that a plugin adds (a `Panels` entry makes it).

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
    overlay_windows: bool = False  # its `windows` are editing aids: none in the clean view

    def draw(self, gui: Gui) -> None:
        """The section's widgets (called while it is open)."""

    def windows(self, gui: Gui) -> None:
        """More ImGui windows beside the panel (the fur timeline), every frame."""

    def attach(self, world: World) -> None:
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


class Spheres(Registry[Callable[["Host"], list[Marker]]]):
    """Instanced spheres to draw this frame."""


class Lines(Registry[Callable[["Host", RenderView], list[np.ndarray]]]):
    """Line-list vertices to join into the frame's line batch."""


class OverlaySpheres(Registry[Callable[["Host"], list[Marker]]]):
    """Instanced spheres that are editing aids (none in the clean view)."""


class OverlayLines(Registry[Callable[["Host", RenderView], list[np.ndarray]]]):
    """Line-list vertices that are editing aids (none in the clean view)."""


class Draws(Registry[Callable[["Host", RenderView], int]]):
    """A plugin's own GL drawing; returns the draw calls it made."""


class FramedPoints(Registry[Callable[["Host"], "np.ndarray | None"]]):
    """Points "frame all" keeps in view besides the creatures."""


class RendererView(Protocol):
    """What a panel uses of the sandbox's renderer."""

    @property
    def camera(self) -> OrbitCamera: ...
    @property
    def state(self) -> dict[str, object]: ...  # plugins' objects kept across worlds


class HudView(Protocol):
    """What a panel uses of the sandbox's HUD."""

    @property
    def width(self) -> int: ...  # pixels of the window the HUD column takes
    def step_tentacle(self, step: int) -> None: ...  # select the next (+1) or previous one


class SandboxView(Protocol):
    """What a HUD section (a `Panels` entry, its `Panel`s) sees of the sandbox: the world
    it draws, the camera and HUD, the window, the keys and mouse, the selection, and
    rebuilding the world from an edited scene or from its scene again (`reset`)
    (`render.sandbox.Sandbox` is one)."""

    @property
    def world(self) -> World: ...

    paused: bool

    @property
    def renderer(self) -> RendererView: ...
    @property
    def hud(self) -> HudView: ...

    window: BaseWindow  # the pyglet window (width, height)
    selection: Selection
    keys: KeyStateHandler  # keys[key.S] is True while S is down

    @property
    def scene(self) -> str | os.PathLike[str] | dict[str, object]: ...  # the world's source
    @property
    def scene_dir(self) -> Path | None: ...
    @property
    def modifiers(self) -> int: ...
    def ground_point(self, x: float, y: float) -> np.ndarray | None: ...
    def pick_creature(self, x: float, y: float) -> int | None: ...
    def select_many(self, creatures: Iterable[int]) -> None: ...
    def rebuild(self, scene: dict[str, object]) -> World: ...
    def reset(self) -> bool: ...  # the world built again from its scene (False: it did not build)


class Panels(Registry[Callable[[SandboxView], list["Panel"]]]):
    """HUD sections, made once per sandbox (the entry gets the sandbox's view)."""


class Clicks(Registry[Callable[["Host", Click], bool]]):
    """Clicks in the 3D view, offered in plugin order until one is taken."""


@dataclass(frozen=True)
class UndoState:
    """A plugin's directable state as the sandbox's undo keeps it."""

    capture: Callable[[Host], object]
    restore: Callable[[Host, object], None]  # narrows what its `capture` gave


class UndoStates(Registry[UndoState]):
    """What the sandbox's undo captures and restores of each plugin."""
