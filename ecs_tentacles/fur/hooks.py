"""Rendering and export hooks: guide polylines, child hairs, controls, take curves.

The renderer and the exporter call these after a frame (the rig system has run):

    curves = guide_curves(world)             # GuideCurves
    curves.points                            # (n_guides, points, 3) float32, world space
    curves.colour, curves.width              # (n_guides, 4) RGBA, (n_guides,) metres
    dense = child_hairs(world)               # the furs' `children` per guide, same layout

Everything returned is a fresh array (safe to keep); empty arrays for a world
without fur.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.fur import children
from ecs_tentacles.fur.components import FurControl
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.take.registries import CurvesFrame

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


@dataclass
class GuideCurves:
    """Polylines to draw: points (n, points, 3), colour (n, 4) RGBA and root width (n,)."""

    points: np.ndarray
    colour: np.ndarray
    width: np.ndarray
    guide: np.ndarray  # (n,) guide row each polyline belongs to (children: their parent)


def guide_curves(world: Host, colour_by: str = "fur") -> GuideCurves:
    """Every guide's world polyline; colour from its fur, or its control's (`"control"`)."""
    fur = world.resource(FurData)
    n = len(fur.guides)
    rows = np.arange(n)
    if colour_by not in ("fur", "control"):
        raise ValueError(f"colour_by must be 'fur' or 'control', got {colour_by!r}")
    source = fur.sets.colour[fur.guides.fur_row]
    if colour_by == "control":
        source = fur.controls.colour[fur.guides.control_row]
    colour = np.ones((n, 4), dtype=np.float32)
    colour[:, :3] = source
    width = fur.sets.width[fur.guides.fur_row].astype(np.float32)
    return GuideCurves(fur.curves[:n].copy(), colour, width, rows)


def child_hairs(
    world: Host,
    per_guide: int | None = None,
    radius: float | None = None,
    seed: int = 0,
    follow: str = "neighbours",
    points: int | None = None,
    guides: np.ndarray | None = None,
) -> GuideCurves:
    """Child hairs around each guide, for visual density (deterministic for `seed`);
    with `guides` (a bool per guide), only the children of those guides, each as it is
    among all of them (the sandbox leaves out the hairs it sees too short to show).

    `follow="neighbours"` (the default): each child grows from the skin near its guide
    and blends its 3 nearest guides (`fur.children`); its colour is jittered per strand.
    `follow="own"`: each child takes its guide's posed curve, moved to a root scattered
    in the skin's tangent plane within `radius` (default: half the guide's length) and
    scaled in length by 0.7-1.0. Either way children follow every rig behaviour and
    the dynamics. `per_guide` defaults to each fur's `children`; `points`: that many
    points per child, picked evenly along the curve (default: all).
    """
    if follow == "neighbours":
        made = children.layout(world, per_guide, seed)
        if guides is not None:
            made = children.subset(made, guides[made.parent])
        base = guide_curves(world)
        colour = base.colour[made.parent].copy()
        colour[:, :3] *= made.jitter[:, None].astype(np.float32)
        curves = children.interpolated_children(world, made, points)
        return GuideCurves(curves, colour, base.width[made.parent] * 0.5, made.parent)
    if follow != "own":
        raise ValueError(f"follow must be 'neighbours' or 'own', got {follow!r}")
    fur = world.resource(FurData)
    g = fur.guides
    parent = children.parents(fur, per_guide)
    rng = np.random.default_rng(seed)
    m = len(parent)
    curves = fur.curves[parent].astype(np.float64)
    frames = fur.frames[parent].astype(np.float64)
    spread = 0.5 * g.length[parent] if radius is None else np.full(m, radius)
    angle = rng.uniform(0.0, 2.0 * np.pi, m)
    reach = spread * np.sqrt(rng.random(m))
    normal = quat_rotate(world.transforms.quat[g.body_row[parent]], g.normal[parent])
    side = frames[:, 2]
    along = np.cross(normal, side)
    offset = reach[:, None] * (np.cos(angle)[:, None] * side + np.sin(angle)[:, None] * along)
    scale = rng.uniform(0.7, 1.0, m)[:, None, None]
    root = curves[:, :1]
    dense = (root + offset[:, None, :] + scale * (curves - root)).astype(np.float32)
    dense = dense[:, children.point_indices(fur.points, points)]
    base = guide_curves(world)
    kept = slice(None) if guides is None else guides[parent]
    return GuideCurves(
        dense[kept], base.colour[parent][kept], base.width[parent][kept] * 0.5, parent[kept]
    )


@dataclass
class ControlMarker:
    """A control as the sandbox draws it: world position, shape, colour and size."""

    entity: int
    name: str
    shape: str
    position: np.ndarray
    colour: np.ndarray
    size: float


def control_markers(world: Host, creature: int | None = None) -> list[ControlMarker]:
    """Every fur control (`creature`: only that creature entity's), placed in world space
    by its creature's mantle pose."""
    fur = world.resource(FurData)
    markers = []
    for entity, control in world.query(FurControl):
        fur_row = control.store.fur_row[control.row]
        if creature is not None and fur.sets.creature[fur_row] != creature:
            continue
        body = fur.sets.body_row[fur_row]
        pos = world.transforms.pos[body] + quat_rotate(
            world.transforms.quat[body], control.position
        )
        markers.append(
            ControlMarker(
                entity, control.name, control.shape, pos, control.colour.copy(), control.size
            )
        )
    return markers


def take_guides(world: Host) -> CurvesFrame | None:
    """The world's fur guide curves as the rig posed them, or None without fur.

    The fur plugin's take track (`ecs_tentacles.fur.outputs`): world polylines (a view
    of the rig's output, which the recorder copies) and root widths (kept along each
    guide, as `guide_curves` gives them); owners from the guides' fur sets.
    """
    fur = world.get_resource(FurData)
    if fur is None or not len(fur.guides):
        return None
    rows = np.asarray(fur.guides.fur_row)
    widths = fur.sets.width[rows].astype(np.float32)[:, None]  # the same along a guide
    owners = np.asarray(fur.sets.creature)[rows]
    return CurvesFrame(points=fur.curves[: len(rows)], widths=widths, creatures=owners)
