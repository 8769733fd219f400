"""The fur tool's panel: controls of the selected creature, their values, display, saving.

A "Fur" section of the HUD (ImGui) over a `fur.editor.FurEditor`: the list of controls
(pick one; or click its marker in the 3D view), creating (count, name, shape, colour,
mirror axis) and deleting, the picked control's position (numeric fields, or drag its
marker over the body) and sliders for lift, aim, direction, random, dynamic and the
emotion weight; display options (colour by control, guides, child hairs, children per
guide); and `Save scene`, which writes the edited scene through the atomic writer.
The timeline (`fur.render.timeline`, a window of this panel) keys the picked control.
The fur plugin's `Panels` entry makes it (`fur_panels`) when the scene has fur;
the display options live in the renderer's state (`fur.render.strands.fur_display`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from imgui_bundle import imgui

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.fur.checks import MAX_SCENE_CHILDREN
from ecs_tentacles.fur.editor import MIRRORS, SHAPES, VALUES, FurEditor
from ecs_tentacles.fur.groom import closest_surface_point
from ecs_tentacles.fur.render.strands import FurDisplay, fur_display
from ecs_tentacles.fur.render.timeline import Timeline
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.render.gui import Gui, same_line_if_fits, text_width
from ecs_tentacles.render.registries import Panel, SandboxView

if TYPE_CHECKING:
    from ecs_tentacles.world import World

PICK_PIXELS = 14  # a click this close to a control's marker picks it


def _conjugate(quat: np.ndarray) -> np.ndarray:
    return np.asarray(quat) * [1.0, -1.0, -1.0, -1.0]


def ray_mantle(origin: np.ndarray, direction: np.ndarray, radius: float, half: float) -> np.ndarray:
    """Where a ray (mantle frame) first meets the mantle cylinder, else its nearest point."""
    hits = []
    a = direction[0] ** 2 + direction[1] ** 2
    if a > 1e-12:  # the wall
        b = 2 * (origin[0] * direction[0] + origin[1] * direction[1])
        c = origin[0] ** 2 + origin[1] ** 2 - radius**2
        disc = b * b - 4 * a * c
        if disc >= 0:
            for t in ((-b - np.sqrt(disc)) / (2 * a), (-b + np.sqrt(disc)) / (2 * a)):
                if t > 0 and abs(origin[2] + t * direction[2]) <= half:
                    hits.append(t)
    if abs(direction[2]) > 1e-12:  # the caps
        for z in (half, -half):
            t = (z - origin[2]) / direction[2]
            point = origin + t * direction
            if t > 0 and point[0] ** 2 + point[1] ** 2 <= radius**2:
                hits.append(t)
    t = min(hits) if hits else max(0.0, -float(origin @ direction))  # nearest to the centre
    return np.asarray(origin + t * direction)


def choice(gui: Gui, name: str, options: tuple[str, ...], current: int) -> tuple[bool, int]:
    """Radio buttons for `options`, wrapped to the panel's width; (changed, index)."""
    changed, chosen = False, current
    for i, option in enumerate(options):
        if i:
            same_line_if_fits(text_width(option))
        if imgui.radio_button(f"{option}##{name}", i == current):
            changed, chosen = True, i
        gui.item(f"{name} {option}")
    return changed, chosen


def fur_panels(sandbox: SandboxView) -> list[Panel]:
    """The fur tool for a sandbox whose scene has fur (none otherwise)."""
    scene = sandbox.world.scene
    if scene is None or not any("fur" in c for c in scene["creatures"]):
        return []
    return [FurPanel(sandbox)]


class FurPanel(Panel):
    """The "Fur" section, its timeline and the 3D picking and dragging of controls."""

    title = "Fur"
    overlay_windows = True  # the keyframe timeline: not in the clean view

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.editor = FurEditor(sandbox.world, sandbox.rebuild)
        self.new_name, self.new_count, self.new_shape = "control", 1, 0
        self.new_colour, self.new_mirror = [0.2, 0.7, 1.0], 0
        name = (sandbox.world.scene or {}).get("name", "scene")
        self.save_path = f"{name}_fur.json"  # in the working folder
        self.message = ""
        self.dragging = False
        self.timeline = Timeline(sandbox, self)
        self.sync_view()

    @property
    def display(self) -> FurDisplay:
        """How the sandbox's renderer draws fur (the display options edit it)."""
        return fur_display(self.sandbox.renderer.state)

    # -- the panel's hooks -----------------------------------------------------------
    def attach(self, world: World) -> None:
        self.editor.attach(world)
        self.sync_view()

    def select(self, creature: int | None, tentacle: int | None) -> None:
        self.select_creature(creature)

    def windows(self, gui: Gui) -> None:
        if self.editor.creature is not None:  # a selection without fur has no timeline
            self.timeline.draw(gui, self.sandbox.hud.width)

    # -- selection -------------------------------------------------------------------
    def select_creature(self, entity: int | None) -> None:
        """Follow the sandbox's selection (a creature without fur shows nothing)."""
        name = None if entity is None else self.sandbox.world.component(entity, Creature).name
        if name != self.editor.creature:
            self.editor.select(name)
        self.sync_view()

    def pick(self, name: str | None) -> None:
        self.editor.control = name
        self.sync_view()

    def sync_view(self) -> None:
        """Highlight the picked control's marker; refresh the fur when paused."""
        display = self.display
        editor = self.editor
        display.selected_control = None
        world = self.sandbox.world
        display.creature = None if editor.creature is None else world.creature(editor.creature)
        if editor.creature is not None and editor.control is not None:
            fur_controls = world.resource(FurData).controls
            display.selected_control = int(fur_controls.entity[editor.rows()[editor.control]])
        self.refresh_rig()

    def refresh_rig(self, edit: bool = False) -> None:
        """Run the rig once so a paused world shows the change.

        `edit`: a value was edited; the tracks stop overwriting it until time moves
        (the timeline scrubs or plays), so it can be keyed.
        """
        world = self.sandbox.world
        from ecs_tentacles.fur.systems.rig import Rig

        rig = world.schedule["rig"]  # the fur rig system: play_tracks pins its clock
        if not isinstance(rig, Rig):
            raise TypeError(f"the schedule's rig is a {type(rig).__name__}, not the fur Rig")
        rig.play_tracks = not edit if self.sandbox.paused else True
        if self.sandbox.paused and len(world.resource(FurData).guides):
            rig.process(world, world.settings.dt)

    # -- the 3D view -----------------------------------------------------------------
    def _mantle(self) -> tuple[np.ndarray, np.ndarray, Creature]:
        world = self.sandbox.world
        entity = self.editor.entity()
        row = world.component(entity, Transform).row
        return (
            world.transforms.pos[row],
            world.transforms.quat[row],
            world.component(entity, Creature),
        )

    def press(self, x: float, y: float) -> bool:
        """Pick the control whose marker is under pixel (x, y); True if one was (drag starts)."""
        editor = self.editor
        if editor.creature is None:
            return False
        pos, quat, _ = self._mantle()
        names = editor.control_names()
        local = np.array([editor.value(n, "position") for n in names])
        world_points = pos + quat_rotate(np.tile(quat, (len(local), 1)), local)
        pixels = self.sandbox.renderer.camera.project(world_points)
        distance = np.linalg.norm(pixels - [x, y], axis=1)
        best = int(np.argmin(distance))
        if distance[best] > PICK_PIXELS:
            return False
        self.pick(names[best])
        self.dragging = True
        return True

    def drag(self, x: float, y: float) -> None:
        """Move the picked control to the body surface under pixel (x, y)."""
        if not self.dragging or self.editor.control is None:
            return
        pos, quat, creature = self._mantle()
        origin, direction = self.sandbox.renderer.camera.ray(x, y)
        back = _conjugate(quat)[None]
        local_origin = quat_rotate(back, (origin - pos)[None])[0]
        local_direction = quat_rotate(back, direction[None])[0]
        radius, height = creature.mantle_radius, creature.mantle_height
        hit = ray_mantle(local_origin, local_direction, radius, height / 2)
        surface, normal = closest_surface_point(hit[None], radius, height)
        size = float(
            self.sandbox.world.resource(FurData).controls.size[
                self.editor.rows()[self.editor.control]
            ]
        )
        self.editor.set_position(self.editor.control, surface[0] + normal[0] * size)
        self.refresh_rig(edit=True)

    def release(self) -> None:
        self.dragging = False

    # -- the panel -------------------------------------------------------------------
    def draw(self, gui: Gui) -> None:
        editor = self.editor
        if editor.creature is None:
            imgui.text("no fur on this creature")
            gui.item("no fur")
            return
        imgui.text(f"controls of {editor.creature}")
        gui.item("controls title")
        for name in editor.control_names():
            twin = editor.source(name)[1] is not None
            label = f"{name} (mirror)" if twin else name
            if imgui.selectable(f"{label}##control", editor.control == name)[0]:
                self.pick(name)
            gui.item(f"control {name}")
        if imgui.button("Delete##control") and editor.control is not None:
            self._try(lambda: editor.delete(str(editor.control)))
        gui.item("delete")
        self._create(gui)
        if editor.control is not None:
            self._edit(gui, editor.control)
        self._display(gui)
        imgui.set_next_item_width(-1.0)
        self.save_path = imgui.input_text("##save path", self.save_path)[1]
        gui.item("save path")
        if imgui.button("Save scene"):
            self._try(lambda: setattr(self, "message", f"saved {editor.save(self.save_path)}"))
        gui.item("save")
        if self.message:
            imgui.text_wrapped(self.message)
            gui.item("message")

    def _try(self, action: Callable[[], object]) -> None:
        try:
            action()
        except (ValueError, KeyError, OSError) as error:
            self.message = f"error: {error}"
        else:
            if not self.message.startswith("saved"):
                self.message = ""
        self.sync_view()

    def _create(self, gui: Gui) -> None:
        opened = imgui.tree_node("Create controls")
        gui.item("create section")
        if not opened:
            return
        width = -1.0
        for label, build in (
            ("name", lambda: imgui.input_text("##name", self.new_name)),
            ("count", lambda: imgui.input_int("##count", self.new_count)),
            ("shape", lambda: choice(gui, "shape", SHAPES, self.new_shape)),
            ("mirror", lambda: choice(gui, "mirror", MIRRORS, self.new_mirror)),
            ("colour", lambda: imgui.color_edit3("##colour", self.new_colour)),
        ):
            imgui.text(label)
            gui.item(f"new {label} label")
            imgui.set_next_item_width(width)
            changed, value = build()
            if label not in ("shape", "mirror"):  # choices record their own buttons
                gui.item(f"new {label}")
            if changed:
                setattr(self, f"new_{label}", max(1, min(value, 16)) if label == "count" else value)
        if imgui.button("Create"):
            self._try(
                lambda: self.editor.create(
                    self.new_name,
                    self.new_count,
                    SHAPES[self.new_shape],
                    tuple(self.new_colour),
                    MIRRORS[self.new_mirror],
                )
            )
        gui.item("create")
        imgui.tree_pop()

    def _edit(self, gui: Gui, name: str) -> None:
        editor = self.editor
        imgui.separator_text(name)
        gui.item("edit title")
        imgui.set_next_item_width(-1.0)
        position = [float(v) for v in editor.value(name, "position")]
        changed, position = imgui.input_float3("##position", position, "%.3f")
        gui.item("position")
        if changed:
            editor.set_position(name, position)
            self.refresh_rig(edit=True)
        for attribute in VALUES:
            label = "emotion weight" if attribute == "emotion" else attribute
            imgui.text(label)
            gui.item(f"{attribute} label")
            imgui.set_next_item_width(-1.0)
            changed, value = imgui.slider_float(
                f"##{attribute}", editor.value(name, attribute), 0.0, 1.0, "%.2f"
            )
            gui.item(attribute)
            if changed:
                editor.set_value(name, attribute, value)
                self.refresh_rig(edit=True)

    def _display(self, gui: Gui) -> None:
        display = self.display
        imgui.separator_text("display")
        gui.item("display title")
        changed, by_control = imgui.checkbox("colour by control", display.colour_by == "control")
        gui.item("colour by control")
        if changed:
            display.colour_by = "control" if by_control else "fur"
        display.guides = imgui.checkbox("guides", display.guides)[1]
        gui.item("guides")
        display.children = imgui.checkbox("child hairs", display.children)[1]
        gui.item("child hairs")
        changed, alone = imgui.checkbox("own guide only", display.follow == "own")
        gui.item("follow own")
        if changed:
            display.follow = "own" if alone else "neighbours"
        world = self.sandbox.world
        own = (
            int(world.resource(FurData).sets.children.max())
            if len(world.resource(FurData).sets)
            else 0
        )
        per_guide = own if display.per_guide is None else display.per_guide
        imgui.text("children per guide")
        gui.item("children label")
        imgui.set_next_item_width(-1.0)
        most = children_slider_most(len(world.resource(FurData).guides))
        changed, per_guide = imgui.slider_int("##children", min(per_guide, most), 0, most)
        gui.item("children")
        if changed:
            display.per_guide = min(per_guide, most)


SLIDER_CHILDREN = 16  # the most child hairs per guide the slider offers


def children_slider_most(guides: int) -> int:
    """The most children per guide the slider offers for a world of `guides` guides: 16,
    or fewer where that would pass the scene's budget of child hairs (`MAX_SCENE_CHILDREN`:
    500,000 guides x 16 would take about 5 GB and 35 s to set up)."""
    return min(SLIDER_CHILDREN, MAX_SCENE_CHILDREN // max(guides, 1))
