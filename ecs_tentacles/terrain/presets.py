"""Ready-made terrains for generated scenes (`ecs-tentacles crowd N --terrain rocky`).

`rocky(positions, reach, seed)`: a noise heightfield under the whole crowd (cells about
`CELL` metres, the default's density; `ROCKY_HEIGHT` from its lowest to its highest
point) with rocks between the creatures' start places, none closer to a start than the
creature's reach; each stands on the ground (the scene's `on_ground` default).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ecs_tentacles.terrain.heights import MAX_RESOLUTION

CELL = 20.0 / 128  # metres between samples: the schema default's density on 20 m
# metres from the lowest to the highest point: twice the tallest mantle a generated crowd
# has (0.25 m) and more, so a hill hides a creature behind it from a camera at its height
ROCKY_HEIGHT = 0.6
NAMES = ("flat", "rocky")


def rocky(positions: np.ndarray, reach: float, seed: int) -> dict[str, Any]:
    """A scene's `terrain` for creatures starting at `positions` (n, 2) within `reach` m."""
    half = np.abs(positions).max(axis=0) + reach + 1.0
    size = [float(round(2 * h, 2)) for h in half]
    resolution = int(np.clip(round(max(size) / CELL) + 1, 3, MAX_RESOLUTION))
    rng = np.random.default_rng(seed)
    rocks = []
    # a rock in some of the gaps between neighbours: where no start is within reach + radius
    for _ in range(len(positions)):
        point = rng.uniform(-half + 0.5, half - 0.5)
        radius = float(rng.uniform(0.12, 0.3))
        if np.min(np.linalg.norm(positions - point, axis=1)) > reach + radius + 0.1:
            rocks.append(
                {
                    "shape": "sphere",
                    "position": [*np.round(point, 3).tolist(), 0.0],
                    "radius": radius,
                }
            )
    return {
        "heightfield": {
            "size": size,
            "resolution": resolution,
            "height": ROCKY_HEIGHT,
            "noise": {"seed": seed, "scale": 4.0, "octaves": 3},
        },
        "obstacles": rocks[:1000],
    }
