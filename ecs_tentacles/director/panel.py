"""The "Director" HUD section and its mouse and keys: place, scatter, remove, copy, grab.

* The palette (`director.palette`): pick a creature or a threat; with "place on click"
  on, a click on the ground places one there (moved to the nearest free spot if it
  would overlap; the log says so).
* S + drag: a density brush scatters the picked creature: under the brush disc it adds
  creatures (seeded, random headings, never overlapping: `director.scatter`) until the
  disc holds "density" creatures per 10 m², at most "count" a stroke.
* Delete: remove the selected creatures. Ctrl+D: a copy of each beside it (selected).
* Ctrl + drag on a creature: grab the body under the pointer and drag it; let go while
  moving to throw it (`director.grab`).

Every one of these is one edit on the sandbox's undo stack (`director.commands`;
Ctrl+Z, Ctrl+Shift+Z). Reads the sandbox's selection, camera and keys; writes the
world through `World.spawn` / `despawn`, the dangers' sources (`behaviour.placeable`) and
the `Director` resource.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np
from imgui_bundle import imgui
from pyglet.window import key

from ecs_tentacles.behaviour import placeable
from ecs_tentacles.components import Creature
from ecs_tentacles.creatures.spawning import SpawnError, creature_entry
from ecs_tentacles.director.commands import Despawned, Moved, Spawned, ThreatDropped
from ecs_tentacles.director.grab import Grab
from ecs_tentacles.director.palette import Preset, presets
from ecs_tentacles.director.scatter import reach_of, scatter
from ecs_tentacles.director.state import Director
from ecs_tentacles.render.gui import Gui
from ecs_tentacles.render.registries import Panel, SandboxView

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.render.undo import Edit
    from ecs_tentacles.world import World

log = logging.getLogger("ecs_tentacles.director")

AREA = 10.0  # m^2 the density is given per


class DirectorPanel(Panel):
    """The palette, the brush settings and the director's mouse and keys."""

    title = "Director"
    order = 15  # after the sandbox's own sections and the fur tool, before terrain

    def __init__(self, sandbox: SandboxView):
        self.sandbox = sandbox
        self.presets: list[Preset] = presets(sandbox.scene_dir)
        self.chosen = 0
        self.placing = False  # a click on the ground places the chosen preset
        self.count = 20  # creatures a scatter stroke adds at most
        self.radius = 2.0  # m: the brush
        self.density = 1.0  # creatures per AREA m^2 the brush fills to
        self.seed = 0
        self.strokes = 0
        self.stroke: list[int] | None = None  # creatures this stroke placed
        self.grab_start: np.ndarray | None = None  # the held creature's joints when grabbed
        self.message = ""

    @property
    def world(self) -> Host:
        world: Host = self.sandbox.world
        return world

    @property
    def preset(self) -> Preset:
        return self.presets[self.chosen]

    def attach(self, world: World) -> None:
        self.stroke, self.grab_start = None, None

    # -- widgets -----------------------------------------------------------------------
    def draw(self, gui: Gui) -> None:
        labels = [p.label for p in self.presets]
        imgui.set_next_item_width(-1)
        _, self.chosen = imgui.combo("##palette", self.chosen, labels)
        gui.item("palette")
        _, self.placing = imgui.checkbox("place on click", self.placing)
        gui.item("place on click")
        for label, name, low, high in (
            ("scatter count", "count", 1, 100),
            ("brush radius m", "radius", 0.5, 10.0),
            ("density /10 m2", "density", 0.1, 5.0),
        ):
            imgui.set_next_item_width(-imgui.calc_text_size(label).x - 8)
            value = getattr(self, name)
            if isinstance(value, int):
                _, value = imgui.slider_int(label, value, int(low), int(high))
            else:
                _, value = imgui.slider_float(label, value, low, high, "%.1f")
            setattr(self, name, value)
            gui.item(name)
        imgui.set_next_item_width(-imgui.calc_text_size("seed").x - 8)
        _, self.seed = imgui.input_int("seed", self.seed)
        gui.item("seed")
        imgui.text_wrapped(
            "S+drag scatter . Ctrl+drag grab/throw . Del remove . Ctrl+D copy"
            " . Ctrl+Z undo . Ctrl+Shift+Z redo . Ctrl+S save"
        )
        if self.message:
            imgui.text_wrapped(self.message)
            gui.item("director message")

    # -- keys --------------------------------------------------------------------------
    def key(self, symbol: int, modifiers: int) -> bool:
        if symbol == key.ESCAPE and self.placing:
            self.placing = False
            return True
        chosen = list(self.sandbox.selection.entities)
        if symbol == key.DELETE and chosen:
            self._push(Despawned.remove(self.world, f"remove {len(chosen)}", chosen))
            self.message = f"removed {len(chosen)} creature(s)"
            return True
        if symbol == key.D and modifiers & key.MOD_CTRL and chosen:
            self.duplicate(chosen)
            return True
        return False

    def duplicate(self, chosen: list[int]) -> list[int]:
        """A copy of each of `chosen` beside it (the free spot nearest); the copies selected."""
        world, made = self.world, []
        for entity in chosen:
            entry = dict(world.creature_specs[entity])
            entry["goals"] = []
            where = np.array(world.transforms.pos[world.creatures.mantle_row[
                world.component(entity, Creature).row]][:2])  # fmt: skip
            step = 2.0 * reach_of(creature_entry(world, entry)) + 0.1
            try:
                made.append(world.spawn(entry, position=where + [step, 0.0], on_overlap="move"))
            except SpawnError as error:  # no free spot near it: said, the others copied
                self.message = str(error).splitlines()[0]
        if not made:
            return made
        self._push(Spawned.of(world, f"copy {len(made)}", made))
        self.sandbox.select_many(made)
        self.message = f"copied {len(made)} creature(s)"
        return made

    # -- the mouse ---------------------------------------------------------------------
    def press(self, x: float, y: float) -> bool:
        sandbox = self.sandbox
        if sandbox.modifiers & key.MOD_CTRL:
            return self._start_grab(x, y)
        ground = sandbox.ground_point(x, y)
        if ground is None:
            return False
        if sandbox.keys[key.S]:
            self.stroke = []
            self.strokes += 1
            self._brush(ground)
            return True
        if self.placing and sandbox.pick_creature(x, y) is None:
            self.place(ground)
            return True
        return False

    def drag(self, x: float, y: float) -> None:
        director = self.world.resource(Director)
        if director.grab is not None:
            origin, direction = self.sandbox.renderer.camera.ray(x, y)
            director.grab.aim(origin, direction)
            return
        ground = self.sandbox.ground_point(x, y)
        if self.stroke is not None and ground is not None:
            self._brush(ground)

    def release(self) -> None:
        director = self.world.resource(Director)
        if director.grab is not None:
            self._end_grab(director)
        if self.stroke is not None:
            director.brush = None
            if self.stroke:
                self._push(Spawned.of(self.world, f"scatter {len(self.stroke)}", self.stroke))
                self.message = f"scattered {len(self.stroke)} {self.preset.label}"
            self.stroke = None

    # -- what they do ------------------------------------------------------------------
    def place(self, ground: np.ndarray) -> int | None:
        """The chosen preset at `ground`: a creature (the nearest free spot) or a threat."""
        world, preset = self.world, self.preset
        if preset.is_threat:
            source = placeable(world)
            if source is None or source.drop is None:
                self.message = "threats are off in this scene"
                return None
            point = [float(v) for v in ground]
            entity = source.drop(world, point, preset.threat)
            name = source.placed(world)[entity] if source.placed else preset.threat
            self._push(ThreatDropped(f"drop {name}", name, point))
            self.message = f"dropped {name}"
            return entity
        try:
            entity = world.spawn(preset.creature(), position=ground[:2], on_overlap="move")
        except SpawnError as error:
            self.message = str(error).splitlines()[0]
            return None
        self._push(Spawned.of(world, f"place {world.creature_name(entity)}", [entity]))
        self.message = f"placed {world.creature_name(entity)}"
        return entity

    def _brush(self, centre: np.ndarray) -> None:
        """Fill the brush disc at `centre` up to the density (at most `count` a stroke)."""
        assert self.stroke is not None
        world, preset = self.world, self.preset
        world.resource(Director).brush = (np.asarray(centre, dtype=float), self.radius)
        if preset.is_threat or len(self.stroke) >= self.count:
            return
        mantles = world.transforms.pos[world.creatures.mantle_row, :2]
        inside = int((np.linalg.norm(mantles - centre[:2], axis=1) <= self.radius).sum())
        wanted = int(self.density * np.pi * self.radius**2 / AREA) - inside
        wanted = min(wanted, self.count - len(self.stroke))
        if wanted <= 0:
            return
        seed = self.seed * 1_000_003 + self.strokes * 1_009 + len(self.stroke)
        try:
            self.stroke += scatter(world, preset.creature(), centre, self.radius, wanted, seed)
        except SpawnError as error:
            self.message = str(error).splitlines()[0]

    def _start_grab(self, x: float, y: float) -> bool:
        sandbox, world = self.sandbox, self.world
        creature = sandbox.pick_creature(x, y)
        if creature is None:
            return False
        origin, direction = sandbox.renderer.camera.ray(x, y)
        view = world.physics.view_of(world.component(creature, Creature))
        bodies = world.transforms.pos[view.body_rows]
        along = np.clip((bodies - origin) @ direction, 0.0, None)
        miss = np.linalg.norm(bodies - (origin + along[:, None] * direction), axis=1)
        body = int(np.argmin(miss))
        point = bodies[body].copy()
        toward = -direction / np.linalg.norm(direction)
        world.resource(Director).grab = Grab(creature, body, point, point.copy(), toward)
        world.physics.lod.promote(creature)
        self.grab_start = view.data.qpos.copy()
        return True

    def _end_grab(self, director: Director) -> None:
        grab, world = director.grab, self.world
        director.grab = None
        assert grab is not None
        if world.try_component(grab.creature, Creature) is None:
            return
        world.physics.lod.release(grab.creature)
        view = world.physics.view_of(world.component(grab.creature, Creature))
        if self.grab_start is not None:
            name = world.creature_name(grab.creature)
            self._push(Moved(f"move {name}", name, self.grab_start, view.data.qpos.copy()))
        self.grab_start = None

    def _push(self, edit: Edit) -> None:
        undo = getattr(self.sandbox, "undo", None)
        if undo is not None:
            undo.push(edit)
