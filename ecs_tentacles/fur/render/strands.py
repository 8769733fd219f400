"""Fur in the sandbox's 3D view: guides and child hairs as ribbons, controls as markers.

The fur plugin's `Lines` and `Draws` entries call `fur_lines` (the controls' marker shapes, joined
into the renderer's line batch while the HUD shows) and `draw_fur` (the strands: one
draw for the guides, one for the child hairs). The GL objects (`FurStrands`: the
ribbon program and two ribbon buffers) are made on the first frame with fur and kept
in the renderer's `view.state`; how fur is drawn (`FurDisplay`, set by the fur panel)
is kept there too. Reads: `FurData` (guides, controls, sets) through `fur.hooks`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.fur.hooks import GuideCurves, child_hairs, guide_curves
from ecs_tentacles.fur.stores import FurData

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.render.registries import RenderView

DISPLAY = "fur.display"  # keys in the renderer's `view.state`
STRANDS = "fur.strands"
# a guide's child hairs are drawn when the guide spans at least this many pixels: a
# crowd framed whole (64 creatures) drew 8,880 hairs a pixel or two long, about 1 ms a
# frame, and 110 pixels of the picture changed by more than a shade without them
CHILD_PIXELS = 3.0


@dataclass
class FurDisplay:
    """How fur is drawn: colour by fur or by control, guides and/or child hairs."""

    colour_by: str = "fur"
    guides: bool = True
    children: bool = True
    per_guide: int | None = None  # child hairs per guide; None: each fur's `children`
    follow: str = "neighbours"  # child hairs blend their 3 nearest guides, or "own"
    child_points: int | None = 3  # points per child hair drawn (level of detail); None: all
    markers: bool = True  # the controls' shapes, while the sandbox shows its overlays (HUD)
    selected_control: int | None = None  # a control entity, drawn highlighted
    # the creature entity the fur tool edits: only its controls are drawn (None: none;
    # a crowd's every control drawn was clutter, and 5 ms a frame at 64 furred creatures)
    creature: int | None = None


def fur_display(state: dict[str, object]) -> FurDisplay:
    """The renderer's fur display settings (`renderer.state` / `view.state`)."""
    display = state.get(DISPLAY)
    if not isinstance(display, FurDisplay):
        display = state[DISPLAY] = FurDisplay()
    return display


def fur_strands(
    world: Host, display: FurDisplay, view: RenderView | None = None
) -> tuple[GuideCurves, GuideCurves]:
    """This frame's guides and child hairs as `display` asks (empty when hidden); seen
    from `view`, only the children of guides at least `CHILD_PIXELS` long on screen."""
    fur = world.get_resource(FurData)  # None with the fur plugin off
    points = max(fur.points, 1) if fur is not None else 1
    empty = GuideCurves(
        np.zeros((0, points, 3), np.float32),
        np.zeros((0, 4), np.float32),
        np.zeros(0, np.float32),
        np.zeros(0, np.int64),
    )
    if fur is None or not len(fur.guides):
        return empty, empty
    guides = guide_curves(world, display.colour_by) if display.guides else empty
    if not display.children:
        return guides, empty
    dense = child_hairs(
        world, display.per_guide, follow=display.follow, points=display.child_points,
        guides=None if view is None else seen_long(fur, view),
    )  # fmt: skip
    if display.colour_by == "control":
        jitter = dense.colour[:, :3] / np.maximum(guide_curves(world).colour[dense.guide, :3], 1e-6)
        dense.colour = guide_curves(world, "control").colour[dense.guide]
        dense.colour[:, :3] *= jitter
    return guides, dense


def seen_long(fur: FurData, view: RenderView) -> np.ndarray | None:
    """A bool per guide: it spans at least `CHILD_PIXELS` pixels seen from `view`'s eye
    (None: the view does not say how big a pixel is)."""
    if view.per_metre <= 0.0:
        return None
    distance = np.linalg.norm(fur.frames[:, 3] - np.asarray(view.eye, np.float32), axis=1)
    return np.asarray(fur.guides.length >= CHILD_PIXELS * view.per_metre * distance)


def fur_lines(world: Host, view: RenderView) -> list[np.ndarray]:
    """The marker shapes (line-list vertices) of the controls of the creature the fur tool
    edits, while the sandbox shows overlays."""
    from ecs_tentacles.fur.render.markers import marker_lines

    fur = world.get_resource(FurData)
    display = fur_display(view.state)
    if fur is None or not len(fur.guides) or not (display.markers and view.overlays):
        return []
    if display.creature is None:
        return []
    return [marker_lines(world, display.selected_control, display.creature)]


class FurStrands:
    """The GL side of the strands: the ribbon program, guides and child hairs."""

    def __init__(self) -> None:
        from ecs_tentacles.fur.render.ribbons import RIBBON_FRAGMENT, RIBBON_VERTEX, Ribbons
        from ecs_tentacles.render.gpu import program

        self.program = program(RIBBON_VERTEX, RIBBON_FRAGMENT)
        self.guides = Ribbons()
        self.children = Ribbons()

    def update(self, world: Host, display: FurDisplay, view: RenderView | None = None) -> None:
        """Upload this frame's strands as `display` asks, seen from `view`."""
        guides, children = fur_strands(world, display, view)
        self.guides.update(guides)
        self.children.update(children)

    def draw(self, view: RenderView) -> int:
        """Guides and child hairs as uploaded: one draw each, both faces (ribbons)."""
        if not (self.guides.count or self.children.count):
            return 0
        from pyglet import gl

        from ecs_tentacles.render.gpu import set_matrix

        prog = self.program
        prog.use()
        set_matrix(prog, "u_view_projection", view.view_projection)
        prog["u_light"] = tuple(np.asarray(view.light, np.float32))
        prog["u_eye"] = tuple(np.asarray(view.eye, np.float32))
        prog["u_min_width"] = float(0.8 * view.pixel)  # about a pixel at the target's distance
        gl.glDisable(gl.GL_CULL_FACE)
        calls = self.guides.draw() + self.children.draw()
        gl.glEnable(gl.GL_CULL_FACE)
        return calls


def strands_of(state: dict[str, object]) -> FurStrands:
    """The renderer's `FurStrands`, made on first use (needs the renderer's GL context)."""
    strands = state.get(STRANDS)
    if not isinstance(strands, FurStrands):
        strands = state[STRANDS] = FurStrands()
    return strands


def draw_fur(world: Host, view: RenderView) -> int:
    """Upload and draw this frame's strands; the draw calls (none without fur)."""
    fur = world.get_resource(FurData)
    if (fur is None or not len(fur.guides)) and STRANDS not in view.state:
        return 0  # no fur, and no GL objects made for it
    strands = strands_of(view.state)
    strands.update(world, fur_display(view.state), view)
    return strands.draw(view)
