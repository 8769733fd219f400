"""The heads-up display: the selected creature, live stats, and the plugins' sections.

Drawn with Dear ImGui (`render.gui`): a panel on the left, as wide as the window
allows, in collapsible sections, one open at a time (opening one folds the others, so
every header stays in view at 720p, whatever a creature brings: `open`, `unfold`).
The HUD's own: "Stats" shows fps, physics ms, simulated time, real-time factor and
attached suckers; "Physics" the groups, threads, recoveries and frozen creatures, the
creatures per level-of-detail tier (coloured as the tier markers: the legend),
promotions and demotions, and the "show tiers" box; "Plugins" the plugins on and every
system, with a box to switch it off. Plugins add sections through `panels`
(`ecs_tentacles.render.registries.Panel`, from their `Panels` entries: locomotion's sliders
and actions, the fur tool), placed by their `order`; `sections` takes bare (title,
draw) pairs and `windows` more ImGui windows. The HUD keeps the selection (a creature,
and one tentacle or all) and tells every panel when it changes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from imgui_bundle import imgui

from ecs_tentacles.components import Creature
from ecs_tentacles.render.gui import Gui, gui_scale, same_line_if_fits
from ecs_tentacles.render.registries import Panel
from ecs_tentacles.render.tiers import text_colour

if TYPE_CHECKING:
    from pyglet.window import BaseWindow

    from ecs_tentacles.world import World

PANEL_WIDTH = 280  # the panel's width at scale 1: under 22 % of a 1280 x 720 window
PANEL_SHARE = 0.4  # the panel never covers more than this share of the window's width
TEXT = (20, 24, 28, 255)
OWN_ORDER = 0  # the HUD's own sections' place among the panels' (`Panel.order`)
SECTION_ORDER = 10  # where bare `sections` go


def panel_width(width: int, height: int, display: float = 1.0) -> int:
    """The HUD panel's width in pixels for a window of this size on a display that asks
    for `display` times larger GUIs (`render.gui.display_scale`)."""
    return int(min(PANEL_WIDTH * gui_scale(height, display), PANEL_SHARE * width))


CLOSED = ("Plugins", "View")  # own and bare sections that start folded
UNSET = "\0"  # `Hud.open` before the first frame


class Hud:
    """The sandbox's panel: the selection, the HUD's own sections and the plugins'."""

    def __init__(self, window: BaseWindow, world: World, *, visible: bool = True):
        self.window = window
        self.world = world
        self.visible = visible
        self.gui = Gui(window)
        self.creature: int | None = None
        self.tentacle: int | None = None  # None: all tentacles
        self.stats: dict[str, float] = {}
        self.panels: list[Panel] = []  # the plugins' sections (the sandbox keeps this list)
        self.sections: list[tuple[str, Callable[[Gui], None]]] = []  # (title, draw)
        self.windows: list[Callable[[Gui], None]] = []  # more ImGui windows (the timeline)
        self._fold: set[str] = set()  # sections to close on the next frame
        # one section open at a time (opening one folds the others): its title, None for
        # all folded, UNSET until the first frame picks the first that starts open
        self.open: str | None = UNSET
        self.name_labels = False  # creatures' names over them (even with the panel hidden)
        # the clean view: no selected creature's name, no panel's editing windows (timeline)
        self.clean = False
        self.label_at: Callable[[], list[tuple[str, float, float]]] = list  # (text, x, y)
        # the selected creature's name over it, while the panel shows (labels off)
        self.selection_label: Callable[[], list[tuple[str, float, float]]] = list
        self.band: tuple[float, float, float, float] | None = None  # a rubber band (pixels)
        self.show_tiers = False  # a marker over each creature, coloured by its physics tier

    # -- selection -------------------------------------------------------------------
    def select(self, creature: int | None, tentacle: int | None = None) -> None:
        """Show and edit `creature` (all its tentacles, or tentacle index `tentacle`)."""
        self.creature, self.tentacle = creature, tentacle
        for panel in self.panels:
            panel.select(creature, tentacle)

    @property
    def title(self) -> str:
        if self.creature is None:
            return "click a creature to select it"
        return str(self.world.component(self.creature, Creature).name)

    def _count(self) -> int:
        return len(self.world.component(self.creature, Creature).tentacles) if self.creature else 0

    def step_tentacle(self, step: int) -> None:
        """Select the next (+1) or previous (-1) tentacle, through "all"."""
        if self.creature is None:
            return
        choices: list[int | None] = [None, *range(self._count())]
        self.select(self.creature, choices[(choices.index(self.tentacle) + step) % len(choices)])

    # -- drawing ---------------------------------------------------------------------
    def update(self, stats: dict[str, float]) -> None:
        """Keep the live numbers for the next draw."""
        self.stats = dict(stats)

    def fold(self, *sections: str) -> None:
        """Close these sections (as a click on their headers would)."""
        self._fold.update(sections)

    def unfold(self, section: str) -> None:
        """Open `section` (the others fold, as a click on its header would do)."""
        self.open = section

    def contains(self, x: float, y: float) -> bool:
        """True when pyglet pixel (x, y) is over the panel (clicks there are not for the world)."""
        return self.visible and (x < self.width or self.gui.contains(x, y))

    @property
    def width(self) -> int:
        """Pixels the panel covers on the left (0 when hidden)."""
        if not self.visible:
            return 0
        return panel_width(self.window.width, self.window.height, self.gui.display)

    def draw(self) -> int:
        """Build and draw the panel; return the GL draw calls it issued."""
        if not self.visible and not self.name_labels and self.band is None:
            self.gui.skip_frame()
            return 0
        self._build()
        if not self.gui.frames or self.gui.remeasure:
            # windows that fit their content know their size from the next build: on the
            # first frame, and when one's content changed (`Gui.measure_again`)
            self.gui.end_frame(draw=False)
            self._build()
        return self.gui.end_frame()

    def _build(self) -> None:
        gui = self.gui
        gui.begin_frame()
        if self.name_labels:
            self._name_labels(self.label_at())
        elif self.visible and not self.clean:  # the selection is the editor's
            self._name_labels(self.selection_label())
        if self.band is not None:
            self._band(*self.band)
        if not self.visible:
            return
        imgui.set_next_window_pos((0.0, 0.0))
        imgui.set_next_window_size((float(self.width), float(self.window.height)))
        flags = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize
        imgui.begin("ecs_tentacles", None, flags | imgui.WindowFlags_.no_collapse)
        gui.window_rect("panel")
        imgui.text(self.title)
        gui.item("title")
        own = [
            (OWN_ORDER, "Stats", self._stats, False),
            (OWN_ORDER, "Physics", self._physics, False),
            (OWN_ORDER, "Plugins", self._plugins, True),
        ]
        plugged = [(p.order, p.title, p.draw, p.closed) for p in self.panels]
        bare = [(SECTION_ORDER, name, build, name in CLOSED) for name, build in self.sections]
        sections = sorted([*own, *plugged, *bare], key=lambda s: s[0])
        if self.open == UNSET:  # the first section that starts open is the one open
            self.open = next((name for _, name, _, closed in sections if not closed), None)
        if self.open in self._fold:
            self.open = None
        self._fold.clear()
        chosen = self.open
        for _, name, build, _ in sections:
            imgui.set_next_item_open(name == self.open, imgui.Cond_.always)
            opened = imgui.collapsing_header(name)
            gui.item(name)
            if opened and name != self.open:
                chosen = name  # opened by a click: the others fold from the next frame
            elif not opened and name == self.open:
                chosen = None if chosen == name else chosen  # folded by a click
            if opened:
                build(gui)
        self.open = chosen
        imgui.end()
        for window in self.windows:
            window(gui)
        for panel in self.panels:
            if not (self.clean and panel.overlay_windows):
                panel.windows(gui)

    def _band(self, x0: float, y0: float, x1: float, y1: float) -> None:
        """The rectangle a drag selects in (pyglet pixels), outlined and tinted."""
        draw = imgui.get_foreground_draw_list()
        height = self.window.height
        corner, other = (min(x0, x1), height - max(y0, y1)), (max(x0, x1), height - min(y0, y1))
        draw.add_rect_filled(corner, other, imgui.get_color_u32((0.6, 0.8, 1.0, 0.12)))
        draw.add_rect(corner, other, imgui.get_color_u32((0.6, 0.8, 1.0, 0.9)))

    def _name_labels(self, labels: list[tuple[str, float, float]]) -> None:
        """Each (text, x, y) centred at its pixel (pyglet's y), on a dark plate."""
        draw = imgui.get_foreground_draw_list()
        pad = 4.0 * self.gui.scale
        for text, x, y in labels:
            size = imgui.calc_text_size(text)
            left, top = x - size.x / 2, self.window.height - y - size.y / 2
            plate = imgui.get_color_u32((0.1, 0.1, 0.12, 0.75))
            draw.add_rect_filled(
                (left - pad, top - pad), (left + size.x + pad, top + size.y + pad), plate, pad
            )
            draw.add_text((left, top), imgui.get_color_u32((1.0, 1.0, 1.0, 1.0)), text)

    def _stats(self, gui: Gui) -> None:
        stats = self.stats
        if stats.get("fps", 0.0) > 0:  # no display: no fps
            imgui.text(f"fps {stats['fps']:.0f}")
            gui.item("fps")
        for name, text in (
            ("physics ms", f"physics {stats.get('physics_ms', 0.0):.1f} ms"),
            ("sim", f"sim {stats.get('sim_time', 0.0):.1f} s"),
            ("rtf", f"real-time x{stats.get('rtf', 0.0):.2f}"),
            ("attached", f"suckers attached {int(stats.get('attached', 0))}"),
        ):
            imgui.text(text)
            gui.item(name)

    def _physics(self, gui: Gui) -> None:
        physics = self.world.physics
        health = physics.health
        for name, text in (
            ("models", f"models {physics.compiles} on {physics.threads} threads"),
            ("recoveries", f"recoveries {health.recoveries}   frozen {health.frozen}"),
        ):
            imgui.text(text)
            gui.item(name)
        self._tiers(gui)

    def _tiers(self, gui: Gui) -> None:
        """Creatures per tier in the markers' colours, tier changes, the "show tiers" box."""
        lod = self.world.lod
        for i, (name, count) in enumerate(lod.counts().items()):
            text = f"{name} {count}"
            if i:
                same_line_if_fits(imgui.calc_text_size(text).x)
            imgui.text_colored(text_colour(name), text)
            gui.item(f"tier {name}")
        if lod.enabled:
            imgui.text(f"promotions {lod.promotions}")
            gui.item("promotions")
            text = f"demotions {lod.demotions}"
            same_line_if_fits(imgui.calc_text_size(text).x)
            imgui.text(text)
            gui.item("demotions")
        else:
            imgui.text("level of detail off")
            gui.item("promotions")
        _, self.show_tiers = imgui.checkbox("show tiers", self.show_tiers)
        gui.item("show tiers")

    def _plugins(self, gui: Gui) -> None:
        """The plugins on, and every system in frame order with a box to switch it off."""
        imgui.text_wrapped("on: " + ", ".join(p.key for p in self.world.plugins))
        gui.item("plugins on")
        schedule = self.world.schedule
        off = set(schedule.disabled())
        for row in schedule.rows():
            name = row["system"].removesuffix(" (disabled)")
            changed, running = imgui.checkbox(f"{row['stage']:<8} {name}", name not in off)
            gui.item(f"system {name}")
            if changed:
                (schedule.enable if running else schedule.disable)(name)

    def close(self) -> None:
        self.gui.close()
