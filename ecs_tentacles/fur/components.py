"""Fur components: views into the fur stores, like `Transform` and `Motor`.

    guide = world.component(entity, FurGuide)
    guide.root                    # (3,) body-local root, a writable view
    guide.points                  # (points, 3) world polyline after the rig ran
    hog = world.creature("hedgehog")
    control = next(c for _, c in world.query(FurControl) if (c.creature, c.name) == (hog, "spine"))
    control.lift = 1.0            # quills up on the next frame

Writing a guide's bind fields (root, normal, rest, side, length, multiplier,
control_row) marks the rig's bind pose stale, so the next frame re-binds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ecs_tentacles.components import RowComponent, RowField
from ecs_tentacles.fur.stores import (
    ControlStore,
    EmotionStore,
    FurData,
    FurSetStore,
    GuideStore,
)


class BindField(RowField):
    """A RowField whose writes bump the fur's version (the rig re-binds)."""

    def __set__(self, component: FurGuide, value: object) -> None:
        super().__set__(component, value)
        component.fur.touch()


@dataclass(eq=False, repr=False)
class FurGuide(RowComponent):
    """A guide curve on a creature's mantle (all vectors in the mantle's local frame)."""

    store: GuideStore
    fur: FurData
    creature: int
    root = BindField()
    normal = BindField()
    rest = BindField()
    side = BindField()
    length = BindField()
    multiplier = BindField()
    control_row = BindField()

    @property
    def points(self) -> np.ndarray:
        """World polyline (points, 3) from the last rig evaluation (float32 view)."""
        points: np.ndarray = self.fur.curves[self.row]
        return points

    @property
    def direction(self) -> np.ndarray:
        """World unit direction of the guide's root after the last rig evaluation."""
        direction: np.ndarray = self.fur.frames[self.row, 0]
        return direction


@dataclass(eq=False, repr=False)
class FurControl(RowComponent):
    """A spatial control: `position` in the creature frame and behaviour values 0..1."""

    store: ControlStore
    name: str
    shape: str
    creature: int
    position = RowField()
    rest_position = RowField()
    lift = RowField()
    aim = RowField()
    direction = RowField()
    random = RowField()
    dynamic = RowField()
    emotion = RowField()
    colour = RowField()
    size = RowField()


@dataclass(eq=False, repr=False)
class Fur(RowComponent):
    """A creature's fur: rig constants (`twist_max` radians, `reach` m...) and its members."""

    store: FurSetStore
    preset: str
    guides: list[int]
    controls: list[int]
    twist_max = RowField()
    reach = RowField()
    min_elevation = RowField()
    stiffness = RowField()
    damping = RowField()
    gravity_scale = RowField()
    erect_lift = RowField()
    erect_random = RowField()
    colour = RowField()
    width = RowField()


@dataclass(eq=False, repr=False)
class Emotion(RowComponent):
    """Fear or aggression of a creature: `level` (about 0..1) and its sensing and timing."""

    store: EmotionStore
    kind: str
    radius = RowField()
    rise = RowField()
    decay = RowField()
    anticipation = RowField()
    level = RowField()
    threatened = RowField()
