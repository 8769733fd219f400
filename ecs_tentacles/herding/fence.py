"""The pen's fence and gate: solid boxes round the pen, and where a creature may cross.

    fence = Fence.of(game)                   # from `HerdingGame` (the scene's `game.pen`)
    fence.boxes()                            # (centres (m, 2), half lengths (m,), angles (m,))
    fence.crossing_ok(starts, goals)         # (n,) bool: no fence between them (or the gate)
    fence.add_to_spec(spec, ...)             # the boxes in a creature's MuJoCo model

The fence runs all round the pen's circle but for the gate, an arc `gate.width` metres
long centred on `gate.heading_deg`. Physics makes it real (the boxes are static geoms
in every creature's model, as the terrain's solids are); the herd's goals respect it
too (`crossing_ok`), so a creature never plans through it and jams.

Reads: the scene's `game.pen` (through `HerdingGame`). Writes: nothing (geoms into a
spec it is handed).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.ground import Ground, StaticContact, StaticSpec
    from ecs_tentacles.herding.game import HerdingGame
    from ecs_tentacles.world import World

PANEL = 0.35  # metres: the longest box of the fence
THICKNESS = 0.05  # metres
CLEAR = 0.3  # metres a creature's goal keeps from the fence (its body is that wide)


@dataclass(frozen=True)
class Fence:
    """A circle of fence round `centre` with a gate of `width` m at `heading` radians."""

    centre: np.ndarray  # (2,)
    radius: float
    heading: float  # radians: from the centre to the gate's middle
    width: float  # metres of the gate's arc
    height: float

    @classmethod
    def of(cls, game: HerdingGame) -> Fence:
        """The fence of a `HerdingGame` (its `pen`, `gate` and `fence` keys)."""
        return cls(
            np.asarray(game.pen_centre, dtype=np.float64),
            float(game.pen_radius),
            float(np.radians(game.gate_heading_deg)),
            float(game.gate_width),
            float(game.fence_height),
        )

    @property
    def half_gate(self) -> float:
        """Radians from the gate's middle to each gate post."""
        return min(np.pi, 0.5 * self.width / self.radius)

    @property
    def gate_point(self) -> np.ndarray:
        """(2,) the middle of the gate, on the pen's circle."""
        return self.centre + self.radius * np.array([np.cos(self.heading), np.sin(self.heading)])

    def in_gate(self, angles: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """(n,) bool: directions (radians from the centre) through the gate, `margin`
        metres clear of its posts (at most a quarter of the gate's width each side)."""
        off = np.angle(np.exp(1j * (np.asarray(angles) - self.heading)))
        clear = min(margin / self.radius, 0.5 * self.half_gate)
        through: np.ndarray = np.abs(off) < self.half_gate - clear
        return through

    def inside(self, xy: np.ndarray) -> np.ndarray:
        """(n,) bool: points (n, 2) inside the pen's circle."""
        inside: np.ndarray = np.hypot(*(np.asarray(xy)[:, :2] - self.centre).T) < self.radius
        return inside

    def boxes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The fence's boxes: centres (m, 2), half lengths (m,), angles (m,) of their
        long axis, tangent to the circle; none across the gate."""
        arc = 2 * np.pi - 2 * self.half_gate  # radians of fence
        count = max(1, int(np.ceil(arc * self.radius / PANEL)))
        step = arc / count
        mids = self.heading + self.half_gate + step * (np.arange(count) + 0.5)
        centres = self.centre + self.radius * np.stack([np.cos(mids), np.sin(mids)], axis=1)
        half = np.full(count, self.radius * np.sin(0.5 * step) + 0.5 * THICKNESS)
        return centres, half, mids + 0.5 * np.pi

    def crossing_ok(self, starts: np.ndarray, goals: np.ndarray) -> np.ndarray:
        """(n,) bool: the straight way from each start (n, 2) to its goal (n, 2) meets
        no fence (it stays on one side, or crosses the circle in the gate, clear of its
        posts), and the goal keeps `CLEAR` m from the fence."""
        a = np.asarray(starts, dtype=np.float64) - self.centre
        d = np.asarray(goals, dtype=np.float64) - self.centre - a
        # |a + t d|^2 = r^2: the circle's crossings, t in [0, 1] on the way
        qa = np.maximum(np.einsum("nk,nk->n", d, d), 1e-12)
        qb = 2 * np.einsum("nk,nk->n", a, d)
        qc = np.einsum("nk,nk->n", a, a) - self.radius**2
        disc = qb * qb - 4 * qa * qc
        root = np.sqrt(np.maximum(disc, 0.0))
        ok = np.ones(len(a), dtype=bool)
        for t in ((-qb - root) / (2 * qa), (-qb + root) / (2 * qa)):
            hits = (disc > 0) & (t >= 0) & (t <= 1)
            where = a + t[:, None] * d
            through = self.in_gate(np.arctan2(where[:, 1], where[:, 0]), CLEAR)
            ok &= ~hits | through
        goal = a + d
        near = np.abs(np.hypot(*goal.T) - self.radius) < CLEAR
        ok_goal: np.ndarray = ok & (~near | self.in_gate(np.arctan2(goal[:, 1], goal[:, 0]), CLEAR))
        return ok_goal

    def add_to_spec(self, spec: StaticSpec, ground: Ground, contact: StaticContact) -> None:
        """The fence's boxes, standing on `ground`, as static geoms `pen/fence<i>`."""
        centres, half, angles = self.boxes()
        base = ground.height(centres)
        for i, (xy, h, angle, z) in enumerate(zip(centres, half, angles, base, strict=True)):
            spec.worldbody.add_geom(
                name=f"pen/fence{i}",
                type=mujoco.mjtGeom.mjGEOM_BOX,
                size=[float(h), 0.5 * THICKNESS, 0.5 * self.height + 0.1],
                pos=[float(xy[0]), float(xy[1]), float(z) + 0.5 * self.height - 0.1],
                quat=[float(np.cos(0.5 * angle)), 0.0, 0.0, float(np.sin(0.5 * angle))],
                **contact.geom(),
            )


def static_geometry(
    world: World,
) -> Callable[[StaticSpec, StaticContact], None]:
    """The herding plugin's `StaticGeometry` entry (`ecs_tentacles.physics.model`): the
    fence in every creature's model; with no other entry (no terrain), the ground too,
    as the model would have had it without any."""
    from ecs_tentacles.ground import ground_of
    from ecs_tentacles.herding.game import HerdingGame
    from ecs_tentacles.physics.model import StaticGeometry

    def add(spec: StaticSpec, contact: StaticContact) -> None:
        ground = ground_of(world)
        if len(list(world.registry(StaticGeometry))) == 1:  # only this one: the plane too
            ground.add_to_spec(spec, contact)
        fence = Fence.of(world.resource(HerdingGame))
        fence.add_to_spec(spec, ground, contact)

    return add
