"""Fur and feathers: guide curves on a creature, spatial controls, the rig, presets.

- `groom`: guides generated on the mantle (or listed), roots in the body frame;
- `controls`: mirrored twins, nearest-control assignment;
- `rig`, `bind`, `dynamics`: the vectorised rig (lift, aim, direction, random
  twist, dynamic blend) run by `ecs_tentacles.fur.systems.rig`; `kernels`: its optional
  numba kernels (used when numba is installed);
- `tracks`: keyframes and easing; `presets`: hedgehog, cat, bird;
- `hooks`: polylines and child hairs for the renderer and the exporter;
- `build`: scene data -> entities; `stores`, `components`: the data.
"""

from __future__ import annotations

from ecs_tentacles.fur.components import Emotion, Fur, FurControl, FurGuide
from ecs_tentacles.fur.hooks import (
    ControlMarker,
    GuideCurves,
    child_hairs,
    control_markers,
    guide_curves,
)
from ecs_tentacles.fur.stores import FurData

__all__ = [
    "ControlMarker",
    "Emotion",
    "Fur",
    "FurControl",
    "FurData",
    "FurGuide",
    "GuideCurves",
    "child_hairs",
    "control_markers",
    "guide_curves",
]
