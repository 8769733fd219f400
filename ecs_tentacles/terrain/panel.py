"""The sandbox's "Terrain" HUD section: place, move and delete obstacles, sculpt the
heightfield, save the scene.

A tool is chosen with its radio button; with one on, a left press in the 3D view acts
where the cursor's ray meets the ground (or an obstacle) instead of selecting:

* box / cylinder / sphere / rock: a new obstacle of the `size` slider, resting there
  (a rock: a noise-displaced boulder, a third of it in the ground);
* move: press on an obstacle, drag, release: it rests where the mouse let go;
* delete: the obstacle under the cursor goes;
* raise / lower / smooth: the brush (radius, strength) acts under the cursor, again
  at every drag step.

Each edit goes through `TerrainEditor` (`ecs_tentacles.terrain.editing`): the physics
models are recompiled, nothing else is rebuilt, the creatures keep going. "Save scene"
writes the scene file with the edits (to the path in the box; in another folder than
the scene's, with copies of the height image and meshes it names beside it).
Reads and writes the terrain through `TerrainEditor`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from imgui_bundle import imgui

from ecs_tentacles.render.gui import Gui, same_line_if_fits, text_width
from ecs_tentacles.render.registries import Panel, SandboxView
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import read_scene_json, resolve_scene_path
from ecs_tentacles.scene.save import default_file_name
from ecs_tentacles.terrain.editing import BRUSHES, SHAPES, TerrainEditError, TerrainEditor

TOOLS = ("none", *SHAPES, "move", "delete", *BRUSHES)


class TerrainPanel(Panel):
    title = "Terrain"
    order = 20
    closed = True

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.tool = "none"
        self.size = 0.6  # metres across a new obstacle
        self.radius = 1.0  # the brush's, metres
        self.strength = 0.03  # metres a brush step raises or lowers at its centre
        self.moving: int | None = None  # the obstacle being moved
        self.last: np.ndarray | None = None  # where the mouse is while moving
        name = (sandbox.world.scene or {}).get("name")  # any string: made a safe file name
        self.save_path = default_file_name(name, "_terrain.json")  # in the current folder
        self.message = ""

    @property
    def editor(self) -> TerrainEditor:
        return self.sandbox.world.resource(TerrainEditor)

    # -- the section ---------------------------------------------------------------------
    def draw(self, gui: Gui) -> None:
        imgui.text("tool (left click in the view)")
        gui.item("tool label")
        for i, tool in enumerate(TOOLS):
            if i:
                same_line_if_fits(text_width(tool))
            if imgui.radio_button(f"{tool}##terrain", self.tool == tool):
                self.tool, self.message = tool, ""
            gui.item(f"terrain tool {tool}")
        for label, attribute, low, high, unit in (
            ("obstacle size", "size", 0.1, 3.0, "m"),
            ("brush radius", "radius", 0.2, 5.0, "m"),
            ("brush strength", "strength", 0.005, 0.2, "m"),
        ):
            imgui.text(label)
            gui.item(f"terrain {attribute} label")
            imgui.set_next_item_width(-1.0)
            changed, value = imgui.slider_float(
                f"##terrain {attribute}", getattr(self, attribute), low, high, f"%.3f {unit}"
            )
            if changed:
                setattr(self, attribute, float(value))
            gui.item(f"terrain {attribute}")
        imgui.text(f"edits {self.editor.edits}")
        gui.item("terrain edits")
        imgui.set_next_item_width(-1.0)
        self.save_path = imgui.input_text("##terrain save path", self.save_path)[1]
        gui.item("terrain save path")
        if imgui.button("Save scene##terrain"):
            self.save()
        gui.item("terrain save")
        if self.message:
            imgui.text_wrapped(self.message)
            gui.item("terrain message")

    # -- the mouse -------------------------------------------------------------------------
    def press(self, x: float, y: float) -> bool:
        if self.tool == "none":
            return False
        point = self.sandbox.ground_point(x, y)
        if point is None:
            return False
        world = self.sandbox.world
        if self.tool == "move":
            self.moving = self.editor.obstacle_at(world, point)
            self.last = None
            self.message = "" if self.moving is not None else "no obstacle there to move"
            return self.moving is not None
        self._act(point)
        return True

    def drag(self, x: float, y: float) -> None:
        point = self.sandbox.ground_point(x, y)
        if point is None:
            return
        if self.tool == "move":
            self.last = point
        elif self.tool in BRUSHES:
            self._act(point)

    def release(self) -> None:
        if self.tool == "move" and self.moving is not None and self.last is not None:
            index, point = self.moving, self.last
            self._try(lambda: self.editor.move(self.sandbox.world, index, point), "moved")
        self.moving, self.last = None, None

    def _act(self, point: np.ndarray) -> None:
        world, editor = self.sandbox.world, self.editor
        if self.tool in SHAPES:
            self._try(lambda: editor.place(world, self.tool, point, self.size), "placed")
        elif self.tool == "delete":
            if editor.delete_at(world, point) is None:
                self.message = "no obstacle there"
        else:
            amount = self.strength if self.tool != "smooth" else 0.5
            self._try(lambda: editor.brush(world, self.tool, point[:2], self.radius, amount), "")

    def _try(self, action: Callable[[], object], done: str) -> None:
        try:
            action()
        except (TerrainEditError, SceneError) as error:
            self.message = f"not done: {' '.join(str(error).split())}"
        else:
            self.message = done

    def save(self) -> None:
        """Write the scene file with the edited terrain to `save_path`."""
        try:
            target = Path(self.save_path)
            raw = self._raw_scene()
            saved = self.editor.save(self.sandbox.world, raw, target)
        except (TerrainEditError, SceneError, OSError) as error:
            self.message = f"not saved: {' '.join(str(error).split())}"
        else:
            self.message = f"saved {saved}"

    def _raw_scene(self) -> dict[str, object]:
        """The scene as its file says (defaults not filled in)."""
        source = self.sandbox.scene
        if isinstance(source, dict):
            return dict(source)
        path = resolve_scene_path(str(source))
        data = read_scene_json(path)  # as a scene is read (SceneError: one line)
        if not isinstance(data, dict):
            raise SceneError([f"{path}: the scene is not an object"])
        return data
