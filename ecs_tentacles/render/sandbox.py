"""The sandbox: a window (or an off-screen one) where players watch, click and tune.

Physics runs at the scene's fixed frame rate with its own accumulator; drawing
happens at display rate and interpolates between the last two physics frames.

Mouse: left-drag orbits, right- or middle-drag pans, wheel zooms; click a creature
to select it, shift-click one to add it to the selection or take it out, shift-drag a
rectangle to select the creatures in it (`render.selection`). Every other click in the
3D view goes to the plugins' `sandbox_click` hooks (`ecs_tentacles.drawing.Click`):
the locomotion plugin's sends the selection to a click on the ground (in formation
when there are several), appends to their paths on shift-click and removes the goal
under a right click. Keys: space pause, . single step, r reset, h HUD, f follow,
a frame all, Ctrl+A select every creature, Esc select none, Ctrl+Z undo and
Ctrl+Shift+Z redo an edit (goals, parameters, the director's; `render.undo`), Ctrl+S
save the roster as a scene (`roster_save`), tab next tentacle, F12 screenshot, v
video, F5 save the state, F9 go back to it. The HUD's panels see keys
and mouse presses first (`Panel.key`, `Panel.press`; `modifiers` and `keys` say what
is held).

Level of detail (`world.lod`): before every physics frame the sandbox tells it the
selected creatures (they run full) and, unless a focus is pinned (`focus=`, `play
--focus`, or the scene's `physics.lod.focus`), a focus of `FOCUS_RADIUS` m around the
camera's target, so what you look at runs full. Headless runs (`play --headless`) do
the same: the camera does not move there, so they stay deterministic; bakes have no
camera and use only the scene's focus.

Plugins add HUD sections (`sandbox_panels`, asked once per plugin and kept across
rebuilds and resets: the locomotion sliders, the fur tool) and draw through the
renderer's hooks; this module names no feature.

User code: a system that raises is disabled and shown in red at the top right (with
a button to run it again) while the sandbox keeps running; a plugin file that changes
is re-imported and swapped in, the world staying as it is (`render.scripts`,
`ecs_tentacles.reload`).

Call `ecs_tentacles.render.configure(headless=...)` before importing this module.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyglet
from pyglet import gl
from pyglet.window import key, mouse
from tqdm import tqdm

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.drawing import Click, Panel
from ecs_tentacles.ground import ground_of
from ecs_tentacles.plugin_registry import sandbox_plugins
from ecs_tentacles.render.hud import Hud
from ecs_tentacles.render.on_screen import creature_at, creatures_in, labels_over
from ecs_tentacles.render.output import VideoWriter, save_png
from ecs_tentacles.render.plugin import RenderPlugin
from ecs_tentacles.render.renderer import Renderer
from ecs_tentacles.render.scripts import Scripts
from ecs_tentacles.render.selection import Selection
from ecs_tentacles.render.undo import UndoStack
from ecs_tentacles.roster_save import save_roster
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.snapshot import SnapshotMismatch
from ecs_tentacles.system import SystemFailure
from ecs_tentacles.world import World

if TYPE_CHECKING:
    from ecs_tentacles.snapshot import Snapshot

CLICK_PIXELS = 4  # a press and release closer than this is a click, not a drag
BUTTONS = {mouse.LEFT: "left", mouse.RIGHT: "right", mouse.MIDDLE: "middle"}
MAX_CATCH_UP = 0.25  # seconds of physics to catch up at most per display frame
DISPLAY_HZ = 60
FOCUS_RADIUS = 4.0  # m around the camera's target where creatures run full physics


class Sandbox:
    """One scene in a window, with the renderer, HUD and input."""

    def __init__(
        self,
        scene: str | os.PathLike[str] | dict[str, Any],
        *,
        width: int = 1280,
        height: int = 720,
        headless: bool = False,
        seed: int | None = None,
        allow_systems: bool = False,
        hud: bool = True,
        lod: bool | None = None,
        focus: tuple[float, float, float] | None = None,
        threads: int | None = None,
    ):
        """`lod` turns level of detail on or off over the scene's (None: the scene's);
        `focus` (x, y, radius in m) pins the full-physics region instead of the camera's;
        `threads` step the physics (None: one per core)."""
        self.threads = threads
        self.scene, self.seed, self.allow_systems = scene, seed, allow_systems
        self.lod, self.focus = lod, focus
        self.headless = headless
        self.window = pyglet.window.Window(
            width, height, caption="ecs_tentacles", visible=not headless, vsync=False
        )
        self.scene_dir: Path | None = None
        self.world = self._build(scene)
        self.scene_dir = self.world.scene_dir  # plugin files of an edited (dict) scene
        self.hud = Hud(self.window, self.world, visible=hud)
        self.hud.label_at = self.creature_labels
        self.hud.selection_label = self.selected_label
        self.scripts = Scripts(self.window)
        self.hud.windows.append(self.scripts.draw)
        self.paused = False
        self.selection = Selection()
        self.panels: dict[str, list[Panel]] = {}  # each plugin's HUD sections, by plugin key
        self._grab: Panel | None = None  # the panel holding the mouse (a dragged marker)
        self._attach_world()
        self.window.push_handlers(self)
        self.window.push_handlers(self.hud.gui)  # the GUI sees every event first
        self.accumulator = 0.0
        self.video: VideoWriter | None = None
        self.screenshots = 0
        self._press: tuple[float, float] | None = None
        self.band: tuple[float, float, float, float] | None = None  # a rectangle being dragged
        self.modifiers = 0  # the modifier keys held at the last mouse press or key
        self.keys = key.KeyStateHandler()  # which keys are down (panels: `keys[key.S]`)
        self.window.push_handlers(self.keys)
        self.stats = {"fps": 0.0, "physics_ms": 0.0, "sim_time": 0.0, "rtf": 0.0, "attached": 0}
        self._wall_start = time.perf_counter()
        self._last_draw: float | None = None
        self.saved_state: Snapshot | None = None

    def _attach_world(self) -> None:
        self.renderer = Renderer(self.world, self.window.width, self.window.height)
        self.renderer.camera.shift_x = self.hud.width / 2
        self._add_sandbox_plugins()
        self.renderer.frame_all()
        self.hud.world = self.world
        self.scripts.attach(self.world)
        self._attach_panels()
        first = self.renderer.creature_entities[0] if self.renderer.creature_entities else None
        self.select(first)

    def _add_sandbox_plugins(self) -> None:
        """The sandbox's own plugins join the world: its drawing, and the ones the
        registry turns on in sandboxes (`plugin_registry.SANDBOX_ON`: the director)."""
        self.world.add_plugin(RenderPlugin(renderer=self.renderer))
        on = {plugin.key for plugin in self.world.plugins}
        for plugin in sandbox_plugins():
            if plugin.key not in on:
                self.world.add_plugin(plugin)
        self.world.events.on("creature_despawned", self._forget)
        self.undo = UndoStack()  # edits name the world they were made in

    def _forget(self, *, creature: int, **_: Any) -> None:
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
        for plugin in self.world.plugins:
            if plugin.key not in self.panels:
                self.panels[plugin.key] = list(plugin.sandbox_panels(self))
        self.hud.panels = [panel for name in names for panel in self.panels[name]]

    def panel(self, title: str) -> Panel | None:
        """The plugins' HUD section titled `title` ("Fur", "Locomotion"), if shown."""
        return next((p for p in self.hud.panels if p.title == title), None)

    def rebuild(self, scene: dict[str, Any]) -> World:
        """Rebuild the world from an edited scene; the camera and the selection stay."""
        selected = self.renderer.selected
        name = None if selected is None else self.world.component(selected, Creature).name
        self.world.close()
        self.saved_state = None  # a snapshot belongs to the world it came from
        self.scene = scene
        self.world = self._build(scene)
        self.renderer.set_world(self.world)
        self._add_sandbox_plugins()
        self.hud.world = self.world
        self.scripts.attach(self.world)
        self._attach_panels()
        self.select(self.world.creature(name) if name is not None else None)
        return self.world

    def _build(self, scene: str | os.PathLike[str] | dict[str, Any]) -> World:
        world = World.from_scene(
            scene,
            seed=self.seed,
            allow_systems=self.allow_systems,
            scene_dir=self.scene_dir,
            lod=self.lod,
            threads=self.threads,
        )
        if self.focus is not None:
            world.lod.focus(self.focus[:2], self.focus[2])
        return world

    @property
    def camera_focus(self) -> bool:
        """True when the level of detail's focus follows the camera (none is pinned)."""
        return self.focus is None and self.world.lod.settings.focus is None

    def steer_lod(self) -> None:
        """Tell the level of detail what the player looks at: the selection, the camera."""
        lod = self.world.lod
        lod.select(self.selection.entities)
        if self.camera_focus:
            lod.focus(self.renderer.camera.target[:2], FOCUS_RADIUS)

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
        if self.paused:
            return
        frame = self.world.settings.dt
        self.accumulator = min(self.accumulator + dt, MAX_CATCH_UP)
        while self.accumulator >= frame:
            self.step(1)
            self.accumulator -= frame

    def save_state(self) -> None:
        """Remember the whole simulation state (F5)."""
        self.saved_state = self.world.snapshot()

    def load_state(self) -> bool:
        """Go back to the state saved with F5 (F9); False if none was saved, or if it
        names a creature removed since (the Scripts window says so)."""
        if self.saved_state is None:
            return False
        try:
            self.world.restore(self.saved_state)
        except SnapshotMismatch as error:
            self.scripts.say(False, str(error))
            return False
        self.world.schedule["render"].process(self.world, 0.0)  # show it now
        self.accumulator = 0.0
        return True

    def reset(self) -> bool:
        """Rebuild the scene from its file (or the fur tool's edited scene).

        If the scene or a plugin's code cannot be built now, the world stays as it is
        and the Scripts window says why (False).
        """
        try:
            world = self._build(self.scene)
        except (SceneError, SystemFailure) as error:
            self.scripts.say(False, f"not reset: {' '.join(str(error).split())}")
            return False
        self.saved_state = None
        self.world.close()
        self.world = world
        self._attach_world()
        return True

    # -- drawing -----------------------------------------------------------------------
    def render(self) -> np.ndarray | None:
        """Draw the world and the HUD off-screen; return the picture if recording."""
        alpha = 1.0 if self.paused else self.accumulator / self.world.settings.dt
        self.renderer.overlays = self.hud.visible  # editing aids (fur control markers)
        self.renderer.show_tiers = self.hud.show_tiers
        self.renderer.draw(alpha)
        self._update_stats()
        gl.glDisable(gl.GL_DEPTH_TEST)
        gl.glDisable(gl.GL_CULL_FACE)
        self.hud.draw()
        pixels = None
        if self.video is not None:
            pixels = self.renderer.target.read()
            self.video.add(pixels)
        if not self.headless:
            self.renderer.target.blit_to_window(*self.window.get_framebuffer_size())
        return pixels

    def on_draw(self) -> None:
        now = time.perf_counter()
        if self._last_draw is not None:
            self.stats["fps"] = 0.9 * self.stats["fps"] + 0.1 / max(now - self._last_draw, 1e-6)
        self._last_draw = now
        self.window.clear()
        self.render()

    def _update_stats(self) -> None:
        wall = time.perf_counter() - self._wall_start
        self.stats["sim_time"] = self.world.time
        self.stats["rtf"] = self.world.time / wall if wall > 0 else 0.0
        self.stats["attached"] = int(self.world.suckers.attached.sum())
        self.hud.update(self.stats)

    def creature_labels(self) -> list[tuple[str, float, float]]:
        """Each creature's name at the pixel above its mantle (for `hud.name_labels`)."""
        return labels_over(self.world, self.renderer, self.renderer.creature_entities)

    def selected_label(self) -> list[tuple[str, float, float]]:
        """The selected creature's name above it (a crowd's one label), or nothing."""
        selected = self.renderer.selected
        return [] if selected is None else labels_over(self.world, self.renderer, [selected])

    def screenshot(self, path: str | os.PathLike[str] | None = None) -> Path:
        """Save what the camera sees (with the HUD) as a PNG."""
        self.render()
        if path is None:
            self.screenshots += 1
            path = f"ecs_tentacles_{self.screenshots:03d}.png"
        return save_png(self.renderer.target.read(), path)

    def toggle_video(self, path: str | os.PathLike[str] | None = None) -> Path | None:
        """Start recording, or stop and return the finished file."""
        if self.video is None:
            target = path or f"ecs_tentacles_{int(time.time())}.mp4"
            self.video = VideoWriter(
                target, self.window.width, self.window.height, self.world.settings.fps
            )
            return None
        video, self.video = self.video, None
        return video.close()

    def save_roster(self, path: str | os.PathLike[str] | None = None) -> Path | None:
        """Write the roster, goals and settings as they are now to a scene file (Ctrl+S:
        `<scene>_directed.json` in the working folder); None and a message if it would
        not load (`ecs_tentacles.roster_save`)."""
        name = (self.world.scene or {}).get("name", "scene")
        target = Path(path) if path is not None else Path(f"{name}_directed.json")
        try:
            saved = save_roster(self.world, target)
        except (SceneError, OSError) as error:
            self.scripts.say(False, f"not saved: {' '.join(str(error).split())}")
            return None
        self.scripts.say(True, f"saved {saved}")
        return saved

    # -- selection and clicks ------------------------------------------------------------
    def select(self, creature: int | None) -> None:
        """Select just `creature` (None: nothing)."""
        self.selection.only(creature)
        self._selection_changed()

    def select_many(self, creatures: Any) -> None:
        """Select `creatures` (entities; the last is the HUD's)."""
        self.selection.replace(creatures)
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

    def click(self, x: float, y: float, button: int, modifiers: int) -> None:
        """What a click at pixel (x, y) does: a left click on a creature selects it; then
        the plugins' `sandbox_click` hooks see it, in plugin order, until one takes it."""
        if self.hud.contains(x, y):
            return
        picked = self.pick_creature(x, y)
        shift = bool(modifiers & key.MOD_SHIFT)
        if button == mouse.LEFT and picked is not None:
            if shift:  # in or out of the selection
                self.selection.toggle(picked)
                self._selection_changed()
                return
            self.select(picked)
        click = Click(
            button=BUTTONS.get(button, "other"),
            shift=shift,
            ground=self.ground_point(x, y),
            creature=picked,
            selected=self.renderer.selected,
            selection=self.selection.entities,
            ctrl=bool(modifiers & key.MOD_CTRL),
        )
        self.undo.record(self.world, "goals", lambda: self._offer(click))

    def _offer(self, click: Click) -> bool:
        """The plugins' `sandbox_click` hooks, in plugin order, until one takes `click`."""
        return any(plugin.sandbox_click(self.world, click) for plugin in self.world.plugins)

    # -- window events -------------------------------------------------------------------
    def on_mouse_press(self, x: int, y: int, button: int, modifiers: int) -> None:
        self.modifiers = modifiers
        self._press = (x, y) if not self.hud.contains(x, y) else None
        if self._press is not None and button == mouse.LEFT:
            for panel in self.hud.panels:
                if panel.press(x, y):  # a fur control's marker: drag it over the body
                    self._press, self._grab = None, panel
                    break

    def on_mouse_release(self, x: int, y: int, button: int, modifiers: int) -> None:
        for panel in self.hud.panels:
            panel.release()
        self._grab = None
        if self.band is not None:
            x0, y0, x1, y1 = self.band
            self.band = self.hud.band = None
            self.select_many(creatures_in(self.world, self.renderer, (x0, y0), (x1, y1)))
        elif (
            self._press is not None
            and np.hypot(x - self._press[0], y - self._press[1]) < CLICK_PIXELS
        ):
            self.click(x, y, button, modifiers)
        self._press = None

    def on_mouse_drag(self, x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        if self._grab is not None:
            self._grab.drag(x, y)
            return
        if self._press is None:
            return
        if buttons & mouse.LEFT and (self.band is not None or modifiers & key.MOD_SHIFT):
            self.band = self.hud.band = (*self._press, float(x), float(y))  # rubber band
        elif buttons & mouse.LEFT:
            self.renderer.camera.orbit(dx, dy)
        elif buttons & (mouse.RIGHT | mouse.MIDDLE):
            self.renderer.camera.pan(dx, dy)

    def on_mouse_scroll(self, x: int, y: int, scroll_x: float, scroll_y: float) -> None:
        if not self.hud.contains(x, y):
            self.renderer.camera.zoom(scroll_y)

    def on_key_press(self, symbol: int, modifiers: int) -> bool | None:
        self._key(symbol, modifiers)
        # Esc clears the selection; pyglet's own handler would close the window
        return pyglet.event.EVENT_HANDLED if symbol == key.ESCAPE else None

    def _key(self, symbol: int, modifiers: int) -> None:
        camera = self.renderer.camera
        if self.hud.visible and self.hud.gui.wants_keyboard:
            return  # typing into a text field
        self.modifiers = modifiers
        if any(panel.key(symbol, modifiers) for panel in self.hud.panels):
            return  # a panel's key (the palette's Delete, Ctrl+Z, ...)
        ctrl, shift = modifiers & key.MOD_CTRL, modifiers & key.MOD_SHIFT
        if symbol == key.A and ctrl:
            self.select_many(self.renderer.creature_entities)
        elif symbol == key.Z and ctrl:
            label = (self.undo.redo if shift else self.undo.undo)(self.world)
            self.scripts.say(True, f"{'redo' if shift else 'undo'}: {label or 'nothing to do'}")
        elif symbol == key.S and ctrl:
            self.save_roster()
        elif symbol == key.ESCAPE:
            self.select(None)
        elif symbol == key.SPACE:
            self.paused = not self.paused
        elif symbol == key.PERIOD:
            self.paused = True
            self.step(1)
        elif symbol == key.R:
            self.reset()
        elif symbol == key.H:
            self.hud.visible = not self.hud.visible
            self.renderer.camera.shift_x = self.hud.width / 2
        elif symbol == key.F and self.renderer.selected is not None:
            row = self.world.component(self.renderer.selected, Transform).row
            camera.follow = None if camera.follow == row else row
        elif symbol == key.A:
            self.renderer.frame_all()
        elif symbol == key.C:
            print(f"view: {self.renderer.toggle_view()}")
        elif symbol == key.TAB:
            self.hud.step_tentacle(-1 if modifiers & key.MOD_SHIFT else 1)
        elif symbol == key.F5:
            self.save_state()
            print(f"state saved at {self.world.time:.2f} s (F9 to go back)")
        elif symbol == key.F9:
            print(f"state restored to {self.world.time:.2f} s" if self.load_state() else
                  "no saved state: F5 saves one")  # fmt: skip
        elif symbol == key.F12:
            print(f"saved {self.screenshot()}")
        elif symbol == key.V:
            finished = self.toggle_video()
            print(f"saved {finished}" if finished else "recording video (v to stop)")

    # -- running -------------------------------------------------------------------------
    def run(self) -> None:
        """Open the window and run until it is closed."""
        pyglet.clock.schedule_interval(self.tick, 1 / 240)  # late calls are fine: dt is real
        pyglet.app.run(1 / DISPLAY_HZ)
        if self.video is not None:
            self.video.close()

    def run_headless(
        self,
        frames: int,
        screenshot: str | os.PathLike[str] | None = None,
        video: str | os.PathLike[str] | None = None,
        progress: bool = True,
    ) -> dict[str, Any]:
        """Step `frames` frames off-screen, recording a video and/or a final screenshot."""
        if video is not None:
            self.toggle_video(video)
        try:
            for _ in tqdm(
                range(frames), unit="frame", disable=None if progress else True, leave=False
            ):
                self.step(1)
                if self.video is not None:
                    self.render()
        except BaseException:
            if self.video is not None:
                self.video.abort()
                self.video = None
            raise
        result: dict[str, Any] = {"frames": frames, "sim_seconds": self.world.time}
        result["tiers"] = self.world.lod.counts()  # creatures per physics tier at the end
        if self.video is not None:
            result["video"] = str(self.toggle_video())
        if screenshot is not None:
            result["screenshot"] = str(self.screenshot(screenshot))
        return result

    def close(self) -> None:
        if self.video is not None:
            self.video.abort()
        self.world.close()
        self.window.switch_to()
        self.hud.close()
        self.window.close()
