"""Ready-made terrains for generated scenes (`ecs-tentacles crowd N --terrain rocky`).

`rocky(positions, reach, seed)`: a noise heightfield under the whole crowd (cells about
`CELL` metres, the default's density; `ROCKY_HEIGHT` from its lowest to its highest
point) with boulders (`rock` obstacles, `ecs_tentacles.terrain.rocks`) in the gaps
between the creatures' start places: `ROCK_WIDTH` m across (a mantle is about 0.3 m),
about one for every `CREATURES_PER_ROCK` creatures, each no closer to a start than the
creature's reach (no tentacle starts inside one) and `PASSAGE` m of open ground between
any two (a creature's body fits through, so the rocks bend its path and never wall it
in). Each is sunk by `BURIED` of its height into the lowest ground under it.
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.terrain.heights import MAX_RESOLUTION

CELL = 20.0 / 128  # metres between samples: the schema default's density on 20 m
# metres from the lowest to the highest point: twice the tallest mantle a generated crowd
# has (0.25 m) and more, so a hill hides a creature behind it from a camera at its height
ROCKY_HEIGHT = 0.6
NAMES = ("flat", "rocky")
ROCK_WIDTH = (0.36, 1.2)  # metres across, the least and the most
CREATURES_PER_ROCK = 1.5
CLEAR = 0.1  # metres between a rock and a creature's reach at the start
# metres of open ground between two rocks: twice navigation's body room (0.45 m) and more,
# so the path finder finds a way between them
PASSAGE = 1.0
MIN_HEIGHT = 0.25  # metres: a small rock still rises above a slope's high side
BURIED = (0.2, 0.4)  # the share of a rock's height under the ground
TRIES = 60  # candidate places per creature


def rocky(positions: np.ndarray, reach: float, seed: int) -> dict[str, object]:
    """A scene's `terrain` for creatures starting at `positions` (n, 2) within `reach` m."""
    half = np.abs(positions).max(axis=0) + reach + 1.0
    size = [float(round(2 * h, 2)) for h in half]
    resolution = int(np.clip(round(max(size) / CELL) + 1, 3, MAX_RESOLUTION))
    return {
        "heightfield": {
            "size": size,
            "resolution": resolution,
            "height": ROCKY_HEIGHT,
            "noise": {"seed": seed, "scale": 4.0, "octaves": 3},
        },
        "obstacles": boulders(positions, reach, half, seed)[:1000],
    }


def boulders(
    positions: np.ndarray, reach: float, half: np.ndarray, seed: int
) -> list[dict[str, object]]:
    """`rock` obstacles within `half` (x, y) of the origin among starts `positions` (n, 2)."""
    rng = np.random.default_rng(seed)
    least, most = 0.5 * ROCK_WIDTH[0], 0.5 * ROCK_WIDTH[1]
    wanted = max(1, round(len(positions) / CREATURES_PER_ROCK))
    candidates = rng.uniform(-half + most, half - most, size=(TRIES * len(positions), 2))
    room = np.full(len(candidates), most)
    if len(positions):  # each candidate's largest radius clear of every start's reach
        gaps = np.linalg.norm(candidates[:, None, :] - positions[None, :, :], axis=2)
        room = np.minimum(room, gaps.min(axis=1) - reach - CLEAR)
    placed: list[tuple[np.ndarray, float]] = []
    rocks: list[dict[str, object]] = []
    for point, fits in zip(candidates, room.tolist(), strict=True):
        if len(rocks) == wanted:
            break
        for centre, radius in placed:
            fits = min(fits, float(np.hypot(*(point - centre))) - radius - PASSAGE)
        if fits < least:
            continue
        radius = min(fits, float(rng.uniform(least, most)))
        across = 2.0 * radius
        # its box: the longest side `across`, the other flatter; sunk into the ground
        width = across * rng.uniform(0.6, 1.0)
        height = min(across, max(MIN_HEIGHT, across * rng.uniform(0.45, 0.8)))
        buried = rng.uniform(*BURIED)
        rocks.append(
            {
                "shape": "rock",
                "position": [*np.round(point, 3).tolist(), round((0.5 - buried) * height, 3)],
                "size": [round(across, 3), round(width, 3), round(height, 3)],
                "rotation_deg": [0.0, 0.0, round(float(rng.uniform(-180.0, 180.0)), 1)],
                "seed": int(rng.integers(0, 2**31 - 1)),
            }
        )
        placed.append((point, radius))
    return rocks
