"""The sandbox: a window (or an off-screen one) where players watch, click and tune.

The window side of a session (`render.session.SandboxSession`: the world, rebuilt and
reset, stepped at the scene's fixed rate with its own accumulator, saved and restored,
its level of detail steered): drawing happens at display rate and interpolates between
the last two physics frames; the sandbox turns the mouse and keys into the session's
calls and the panels' (`render.registries.SandboxView` is what panels see of it).

Each frame's picture (drawn into the off-screen target, shown, kept as a PNG or an
MP4) is `render.sandbox_picture`. The mouse and the keys are `render.sandbox_input`
(selecting one creature or many, goal clicks through the plugins' `Clicks` entries
as undoable edits, the HUD's panels seeing presses and keys first, the key map).

Level of detail (`world.lod`): before every physics frame the sandbox tells it the
selected creatures (they run full) and, unless a focus is pinned (`focus=`, `play
--focus`, or the scene's `physics.lod.focus`), a focus of `session.FOCUS_RADIUS` m around the
camera's target: the creatures there run full and the others at most reduced (the
full budget is not filled with creatures the camera is not on: a crowd framed whole
then keeps real time), so what you look at runs full. Headless runs (`play
--headless`) do the same: the camera does not move there, so they stay deterministic;
bakes have no camera and use only the scene's focus.

Plugins add HUD sections (`Panels` entries, `ecs_tentacles.render.registries`, made
once per plugin and kept across rebuilds and resets: the locomotion sliders, the fur
tool) and draw through the renderer's registries; this module names no feature.

User code: a system that raises is disabled and shown in red at the top right (with
a button to run it again) while the sandbox keeps running; a plugin file that changes
is re-imported and swapped in, the world staying as it is (`render.scripts`,
`ecs_tentacles.reload`).

Call `ecs_tentacles.render.configure(headless=...)` before importing this module.
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyglet
from imgui_bundle import imgui
from pyglet.window import key
from tqdm import tqdm

from ecs_tentacles.components import Creature
from ecs_tentacles.ground import ground_of
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.render.camera import CameraChoice
from ecs_tentacles.render.gui import Gui, same_line_if_fits, text_width
from ecs_tentacles.render.hud import Hud
from ecs_tentacles.render.on_screen import creature_at
from ecs_tentacles.render.plugin import RenderPlugin
from ecs_tentacles.render.registries import Panel, Panels
from ecs_tentacles.render.renderer import Renderer
from ecs_tentacles.render.sandbox_input import SandboxInput
from ecs_tentacles.render.sandbox_picture import SandboxPicture
from ecs_tentacles.render.scripts import Scripts
from ecs_tentacles.render.selection import Selection
from ecs_tentacles.render.session import SandboxSession
from ecs_tentacles.render.undo import UndoStack
from ecs_tentacles.scene.plugins import sandbox_plugins
from ecs_tentacles.skin.colours import PALETTES
from ecs_tentacles.world import World

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Mapping

FRAME_EASE = 0.08  # share of the way to the new framing a video frame moves (frame-all)
DISPLAY_HZ = 60


def scene_palette(scene: Mapping[str, object] | None) -> str:
    """The creature palette a scene asks for (`render.palette`), natural if none."""
    render = (scene or {}).get("render")
    return str(render.get("palette", "natural")) if isinstance(render, dict) else "natural"


def is_game(scene: Mapping[str, object] | None) -> bool:
    """Whether a validated scene is a game's (it has a `game` key): its view starts clean."""
    return scene is not None and bool(scene.get("game"))


class Sandbox(SandboxPicture):
    """One scene in a window, with the renderer, HUD and input."""

    def __init__(
        self,
        scene: str | os.PathLike[str] | dict[str, object],
        options: WorldOptions | None = None,
        *,
        width: int = 1280,
        height: int = 720,
        headless: bool = False,
        hud: bool = True,
        palette: str | None = None,
        clean: bool | None = None,
        **deprecated: object,
    ):
        """`options` build its worlds (`ecs_tentacles.options.WorldOptions`: seed, code
        allowed, threads, level of detail; a `focus` pins the full-physics region instead
        of the camera's); `palette` colours the creatures
        ("natural" or "debug": `ecs_tentacles.skin.colours`; None: the scene's `render.palette`,
        natural if it says none); `clean` starts in the clean view, without the editor's
        overlays (None: a game's scene, one with a `game` key, starts clean; o toggles).
        (`seed=`, `lod=`... as keywords: deprecated, `WorldOptions.given`.)"""
        options = (options or WorldOptions()).given(deprecated, "Sandbox")
        self.headless = headless
        self.window = pyglet.window.Window(
            width, height, caption="ecs_tentacles", visible=not headless, vsync=False
        )
        # the simulation (world, rebuild, reset, stepping, saves): `render.session`
        self.session = SandboxSession(
            scene, options, say=lambda ok, text: self.scripts.say(ok, text)
        )
        # the clean view (`render.registries`: a picture for showing), kept across resets
        self.clean: bool = is_game(self.world.scene) if clean is None else clean
        self.hud = Hud(self.window, self.world, visible=hud)
        self.hud.label_at = self.creature_labels
        self.hud.selection_label = self.selected_label
        self.scripts = Scripts(self.window)
        self.hud.windows.append(self.scripts.draw)
        self.hud.sections.append(("View", self._view_section))
        self.selection = Selection()
        self.panels: dict[str, list[Panel]] = {}  # each plugin's HUD sections, by plugin key
        self.camera_choice: CameraChoice | None = None  # `aim`'s, kept across resets
        # kept across resets (the HUD's View section changes it)
        self.palette = palette if palette is not None else scene_palette(self.world.scene)
        self._attach_world()
        self.input = SandboxInput(self)  # the mouse and the keys
        self.window.push_handlers(self)  # (on_draw)
        self.window.push_handlers(self.input)
        self.window.push_handlers(self.hud.gui)  # the GUI sees every event first
        self._start_picture()
        self.keys = key.KeyStateHandler()  # which keys are down (panels: `keys[key.S]`)
        self.window.push_handlers(self.keys)

    # -- the session's state, as panels and scripts read it -----------------------------
    @property
    def scene(self) -> str | os.PathLike[str] | dict[str, object]:
        """What the world was built from (a file, a bundled name or an edited scene)."""
        return self.session.scene

    @property
    def scene_dir(self) -> Path | None:
        return self.session.scene_dir

    @property
    def paused(self) -> bool:
        return self.session.paused

    @paused.setter
    def paused(self, value: bool) -> None:
        self.session.paused = value

    def aim(self, choice: CameraChoice | None) -> None:
        """Put the camera where `choice` says (`play --camera`), now and after a reset;
        None: every creature framed. KeyError (one line) when it follows a creature this
        world does not have."""
        renderer = self.renderer
        if choice is None or choice.kind == "frame-all":
            renderer.frame_all()
        elif choice.kind == "follow":
            assert choice.name is not None
            renderer.follow(self.world.creature(choice.name))
        else:
            renderer.camera.look_from(np.array(choice.eye), np.array(choice.target))
        self.camera_choice = choice

    def _view_section(self, gui: Gui) -> None:
        """The HUD's "View": the clean view and the creatures' palette."""
        _, self.clean = imgui.checkbox("clean view (o)", self.clean)
        gui.item("clean view")
        imgui.text("colours")
        gui.item("colours")
        for name in PALETTES:
            same_line_if_fits(text_width(name))
            if imgui.radio_button(name, self.renderer.palette == name):
                self.palette = name
                self.renderer.set_palette(name)
            gui.item(f"palette {name}")

    def _attach_world(self) -> None:
        self.renderer = Renderer(self.world, self.window.width, self.window.height)
        self.renderer.set_palette(self.palette)
        self.renderer.camera.shift_x = self.hud.width / 2
        self._add_sandbox_plugins()
        self.renderer.frame_all()
        self.hud.world = self.world
        self.scripts.attach(self.world)
        self._attach_panels()
        if self.camera_choice is not None:  # after a reset, as asked
            self.aim(self.camera_choice)
        first = self.renderer.creature_entities[0] if self.renderer.creature_entities else None
        self.select(first)

    def _add_sandbox_plugins(self) -> None:
        """The sandbox's own plugins join the world: its drawing, and the engine's plugins
        of the entry-point group `ecs_tentacles.plugins.sandbox` (the director)."""
        self.world.add_plugin(RenderPlugin(renderer=self.renderer))
        on = {plugin.key for plugin in self.world.plugins}
        for plugin in sandbox_plugins():
            if plugin.key not in on:
                self.world.add_plugin(plugin)
        self.world.events.on("creature_despawned", self._forget)
        self.undo = UndoStack()  # edits name the world they were made in

    def _forget(self, *, creature: int, **_: object) -> None:
        """A despawned creature leaves the selection."""
        if creature in self.selection:
            self.selection.discard(creature)
            self._selection_changed()

    def _attach_panels(self) -> None:
        """Tell the kept panels about the new world; ask plugins seen first for theirs."""
        names = [plugin.key for plugin in self.world.plugins]
        for name in names:
            for panel in self.panels.get(name, []):
                panel.attach(self.world)
        made: dict[str, list[Panel]] = {}
        for owner, make in self.world.registry(Panels).items():
            if owner not in self.panels:
                made.setdefault(owner, []).extend(make(self))
        self.panels.update(made)
        for name in names:
            self.panels.setdefault(name, [])  # seen: a plugin's panels are made once
        self.hud.panels = [panel for name in names for panel in self.panels[name]]

    def panel(self, title: str) -> Panel | None:
        """The plugins' HUD section titled `title` ("Fur", "Locomotion"), if shown."""
        return next((p for p in self.hud.panels if p.title == title), None)

    def rebuild(self, scene: dict[str, object]) -> World:
        """Rebuild the world from an edited scene; the camera and the selection stay."""
        selected = self.renderer.selected
        name = None if selected is None else self.world.component(selected, Creature).name
        self.session.rebuild(scene)
        self.renderer.set_world(self.world)
        self._add_sandbox_plugins()
        self.hud.world = self.world
        self.scripts.attach(self.world)
        self._attach_panels()
        self.select(self.world.creature(name) if name is not None else None)
        return self.world

    @property
    def camera_focus(self) -> bool:
        """True when the level of detail's focus follows the camera (none is pinned)."""
        return self.session.camera_focus

    def steer_lod(self) -> None:
        """Tell the level of detail what the player looks at: the selection, the camera."""
        camera = self.renderer.camera
        self.session.steer_lod(camera.target, self.selection.entities, camera.distance)

    # -- simulation --------------------------------------------------------------------
    def step(self, frames: int = 1) -> None:
        """Advance the world by whole physics frames; a system that raises is disabled."""
        start = time.perf_counter()
        self.steer_lod()
        self.world.step(frames, on_failure=self.scripts.failed)
        self.stats["physics_ms"] = 1000 * (time.perf_counter() - start) / frames

    def tick(self, dt: float) -> None:
        """Clock callback: reload changed plugin files, run the physics frames that are due."""
        self.scripts.poll()
        for _ in range(self.session.due(dt)):
            self.step(1)

    def save_state(self) -> None:
        """Remember the whole simulation state (F5)."""
        self.session.save_state()

    def load_state(self) -> bool:
        """Go back to the state saved with F5 (F9); False if none was saved, or if it
        names a creature removed since (the Scripts window says so)."""
        if not self.session.load_state():
            return False
        self.world.schedule["render"].process(self.world, 0.0)  # show it now
        return True

    def reset(self) -> bool:
        """Rebuild the scene from its file (or the fur tool's edited scene).

        If the scene or a plugin's code cannot be built now, the world stays as it is
        and the Scripts window says why (False).
        """
        if self.session.reset() is None:
            return False
        self._attach_world()
        return True

    def save_roster(self, path: str | os.PathLike[str] | None = None) -> Path | None:
        """Write the world as it is now to a scene file (Ctrl+S; `SandboxSession.save_roster`)."""
        return self.session.save_roster(path)

    @property
    def modifiers(self) -> int:
        """The modifier keys held at the last mouse press or key (panels read it)."""
        return self.input.modifiers

    # -- selection -----------------------------------------------------------------------
    def select(self, creature: int | None) -> None:
        """Select just `creature` (None: nothing)."""
        self.selection.only(creature)
        self._selection_changed()

    def select_many(self, creatures: Iterable[int]) -> None:
        """Select `creatures` (entities; the last is the HUD's)."""
        self.selection.replace(creatures)
        self._selection_changed()

    def toggle(self, creature: int) -> None:
        """Add `creature` to the selection, or take it out (shift-click)."""
        self.selection.toggle(creature)
        self._selection_changed()

    def _selection_changed(self) -> None:
        primary = self.selection.primary
        self.renderer.selected = primary
        self.renderer.selection = self.selection.entities
        self.hud.select(primary)  # and every panel

    def pick_creature(self, x: float, y: float) -> int | None:
        """The creature whose mantle is under pixel (x, y), nearest first."""
        return creature_at(self.world, self.renderer, x, y)

    def ground_point(self, x: float, y: float) -> np.ndarray | None:
        """Where the ray through pixel (x, y) first meets the ground: the terrain or an
        obstacle when the world has them (the plane z = 0 past their edge)."""
        origin, direction = self.renderer.camera.ray(x, y)
        hit = ground_of(self.world).ray(origin, direction)
        return hit if hit is not None else self.renderer.camera.ground_point(x, y)

    # -- running -------------------------------------------------------------------------
    def run(self) -> None:
        """Open the window and run until it is closed (Ctrl+Q, or Ctrl-C in the terminal,
        closes it as its close button does: a video being recorded is finished)."""
        pyglet.clock.schedule_interval(self.tick, 1 / 240)  # late calls are fine: dt is real
        before = signal.signal(signal.SIGINT, lambda *_: self.quit())
        try:
            pyglet.app.run(1 / DISPLAY_HZ)
        finally:
            signal.signal(signal.SIGINT, before)
        if self.video is not None:
            self.video.close()

    def quit(self) -> None:
        """Leave `run` at the end of this frame, as closing the window does."""
        pyglet.app.exit()

    def run_headless(
        self,
        frames: int,
        screenshot: str | os.PathLike[str] | None = None,
        video: str | os.PathLike[str] | None = None,
        progress: bool = True,
        until: Callable[[World], bool] | None = None,
    ) -> dict[str, object]:
        """Step `frames` frames off-screen, recording a video and/or a final screenshot;
        with `until`, stop after the first frame at which `until(world)` is True (a game
        won or lost). `frames` in the result: the frames run."""
        if video is not None:
            self.toggle_video(video)
        physics_ms = []
        done = 0
        try:
            for _ in tqdm(
                range(frames), unit="frame", disable=None if progress else True, leave=False
            ):
                self.step(1)
                done += 1
                physics_ms.append(self.stats["physics_ms"])
                if self.video is not None:
                    self.keep_framed(FRAME_EASE)
                    self.render()
                if until is not None and until(self.world):
                    break
        except BaseException:
            if self.video is not None:
                self.video.abort()
                self.video = None
            raise
        result: dict[str, object] = {"frames": done, "sim_seconds": self.world.time}
        result["tiers"] = self.world.lod.counts()  # creatures per physics tier at the end
        # a frame's physics, median over the run: at most the frame's duration keeps real time
        median = float(np.median(physics_ms))
        result["physics_ms"] = round(median, 2)
        result["realtime_factor"] = round(1000.0 * self.world.settings.dt / median, 3)
        if self.video is not None:
            result["video"] = str(self.toggle_video())
        if screenshot is not None:
            self.keep_framed()
            result["screenshot"] = str(self.screenshot(screenshot))
        return result

    def close(self) -> None:
        if self.video is not None:
            self.video.abort()
        self.world.close()
        self.window.switch_to()
        self.hud.close()
        self.window.close()
