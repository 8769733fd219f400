"""The sandbox's mouse and keys (`Sandbox.input`, a pyglet handler on its window).

Mouse: left-drag selects the creatures in a rectangle (drawn by the HUD while it is
dragged; with shift they are added to the selection), right-drag orbits, middle- or
shift+right-drag pans, wheel zooms; a click on a creature selects it, shift-click adds
it to the selection or takes it out; every other click
goes to the plugins' `Clicks` entries as one undoable edit. A left press is
offered to the HUD's panels first (`Panel.press`: a fur marker, the director's tools),
and keys too (`Panel.key`). Keys: space pause, . single step, r reset, h HUD,
f follow, a frame all, Ctrl+A select every creature, Esc select none, Ctrl+Z /
Ctrl+Shift+Z undo / redo, Ctrl+S save the roster, c skinned / capsules, tab next
tentacle, F5 / F9 save / restore the state, F12 screenshot, v video, o the clean view
(the editor's overlays hidden or shown again), Ctrl+Q quit (as closing the window does).
Reads and writes only through the sandbox.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pyglet
from pyglet.window import key, mouse

from ecs_tentacles.components import Transform
from ecs_tentacles.creatures.spawning import SpawnError
from ecs_tentacles.render.on_screen import creatures_in
from ecs_tentacles.render.registries import Click, Clicks, Panel

CLICK_PIXELS = 4  # a press and release closer than this is a click, not a drag
BUTTONS = {mouse.LEFT: "left", mouse.RIGHT: "right", mouse.MIDDLE: "middle"}


class SandboxInput:
    """What the mouse and keys do in a sandbox (module docstring)."""

    def __init__(self, sandbox: Any):  # a `render.sandbox.Sandbox` (which imports this)
        self.sandbox = sandbox
        self.modifiers = 0  # the modifier keys held at the last mouse press or key
        self.band: tuple[float, float, float, float] | None = None  # a rectangle being dragged
        self._press: tuple[float, float] | None = None
        self._grab: Panel | None = None  # the panel holding the mouse (a dragged marker)

    def click(self, x: float, y: float, button: int, modifiers: int) -> None:
        """What a click at pixel (x, y) does: a left click on a creature selects it; then
        the plugins' `Clicks` entries see it, in plugin order, until one takes it."""
        sandbox = self.sandbox
        if sandbox.hud.contains(x, y):
            return
        picked = sandbox.pick_creature(x, y)
        shift = bool(modifiers & key.MOD_SHIFT)
        if button == mouse.LEFT and picked is not None:
            if shift:  # in or out of the selection
                sandbox.toggle(picked)
                return
            sandbox.select(picked)
        click = Click(
            button=BUTTONS.get(button, "other"),
            shift=shift,
            ground=sandbox.ground_point(x, y),
            creature=picked,
            selected=sandbox.renderer.selected,
            selection=sandbox.selection.entities,
            ctrl=bool(modifiers & key.MOD_CTRL),
        )
        try:
            sandbox.undo.record(sandbox.world, "goals", lambda: self._offer(click))
        except ValueError as refused:  # e.g. a formation with no room there: say so, go on
            sandbox.scripts.say(False, f"click refused: {refused}")

    def _offer(self, click: Click) -> bool:
        """The plugins' `Clicks` entries, in plugin order, until one takes `click`."""
        world = self.sandbox.world
        return any(take(world, click) for take in world.registry(Clicks))

    def on_mouse_press(self, x: int, y: int, button: int, modifiers: int) -> None:
        sandbox = self.sandbox
        self.modifiers = modifiers
        self._press = (x, y) if not sandbox.hud.contains(x, y) else None
        if self._press is not None and button == mouse.LEFT:
            for panel in sandbox.hud.panels:
                if panel.press(x, y):  # a fur control's marker: drag it over the body
                    self._press, self._grab = None, panel
                    break

    def on_mouse_release(self, x: int, y: int, button: int, modifiers: int) -> None:
        sandbox = self.sandbox
        for panel in sandbox.hud.panels:
            panel.release()
        self._grab = None
        if self.band is not None:
            x0, y0, x1, y1 = self.band
            self.band = sandbox.hud.band = None
            inside = creatures_in(sandbox.world, sandbox.renderer, (x0, y0), (x1, y1))
            if modifiers & key.MOD_SHIFT:  # held as the band is let go: added to the selection
                inside = [*sandbox.selection.entities, *inside]
            sandbox.select_many(inside)
        elif (
            self._press is not None
            and np.hypot(x - self._press[0], y - self._press[1]) < CLICK_PIXELS
        ):
            self.click(x, y, button, modifiers)
        self._press = None

    def on_mouse_drag(self, x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        sandbox = self.sandbox
        if self._grab is not None:
            self._grab.drag(x, y)
            return
        if self._press is None:
            return
        if buttons & mouse.LEFT:  # a rubber band, once the pointer is past a click's jitter
            x0, y0 = self._press
            if self.band is not None or np.hypot(x - x0, y - y0) >= CLICK_PIXELS:
                self.band = sandbox.hud.band = (x0, y0, float(x), float(y))
        elif buttons & mouse.RIGHT and not modifiers & key.MOD_SHIFT:
            sandbox.renderer.camera.orbit(dx, dy)
        elif buttons & (mouse.RIGHT | mouse.MIDDLE):
            sandbox.renderer.camera.pan(dx, dy)

    def on_mouse_scroll(self, x: int, y: int, scroll_x: float, scroll_y: float) -> None:
        sandbox = self.sandbox
        if not sandbox.hud.contains(x, y):
            sandbox.renderer.camera.zoom(scroll_y)

    def on_key_press(self, symbol: int, modifiers: int) -> bool | None:
        self._key(symbol, modifiers)
        # Esc clears the selection; pyglet's own handler would close the window
        return pyglet.event.EVENT_HANDLED if symbol == key.ESCAPE else None

    def _key(self, symbol: int, modifiers: int) -> None:
        sandbox = self.sandbox
        camera = sandbox.renderer.camera
        if sandbox.hud.visible and sandbox.hud.gui.wants_keyboard:
            return  # typing into a text field
        self.modifiers = modifiers
        if any(panel.key(symbol, modifiers) for panel in sandbox.hud.panels):
            return  # a panel's key (the palette's Delete, Ctrl+Z, ...)
        ctrl, shift = modifiers & key.MOD_CTRL, modifiers & key.MOD_SHIFT
        if symbol == key.A and ctrl:
            sandbox.select_many(sandbox.renderer.creature_entities)
        elif symbol == key.Z and ctrl:
            what = "redo" if shift else "undo"
            try:
                label = (sandbox.undo.redo if shift else sandbox.undo.undo)(sandbox.world)
            except SpawnError as refused:  # no free spot to put a creature back
                sandbox.scripts.say(False, f"{what} refused: {refused}")
            else:
                sandbox.scripts.say(True, f"{what}: {label or 'nothing to do'}")
        elif symbol == key.S and ctrl:
            sandbox.save_roster()
        elif symbol == key.Q and ctrl:
            sandbox.quit()
        elif symbol == key.ESCAPE:
            sandbox.select(None)
        elif symbol == key.SPACE:
            sandbox.paused = not sandbox.paused
        elif symbol == key.PERIOD:
            sandbox.paused = True
            sandbox.step(1)
        elif symbol == key.R:
            sandbox.reset()
        elif symbol == key.H:
            sandbox.hud.visible = not sandbox.hud.visible
            sandbox.renderer.camera.shift_x = sandbox.hud.width / 2
        elif symbol == key.F and sandbox.renderer.selected is not None:
            row = sandbox.world.component(sandbox.renderer.selected, Transform).row
            camera.follow = None if camera.follow == row else row
        elif symbol == key.A:
            sandbox.renderer.frame_all()
        elif symbol == key.C:
            print(f"view: {sandbox.renderer.toggle_view()}")
        elif symbol == key.TAB:
            sandbox.hud.step_tentacle(-1 if modifiers & key.MOD_SHIFT else 1)
        elif symbol == key.F5:
            sandbox.save_state()
            print(f"state saved at {sandbox.world.time:.2f} s (F9 to go back)")
        elif symbol == key.F9:
            print(f"state restored to {sandbox.world.time:.2f} s" if sandbox.load_state() else
                  "no saved state: F5 saves one")  # fmt: skip
        elif symbol == key.F12:
            print(f"saved {sandbox.screenshot()}")
        elif symbol == key.O:
            sandbox.clean = not sandbox.clean
            print(f"clean view {'on' if sandbox.clean else 'off'} (o)")
        elif symbol == key.V:
            finished = sandbox.toggle_video()
            print(f"saved {finished}" if finished else "recording video (v to stop)")
