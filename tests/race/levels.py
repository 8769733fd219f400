"""Small race levels for the tests: two small creatures on the plane, quick to build."""

from __future__ import annotations

import copy
from typing import Any

CREATURE = {
    "mantle": {"radius": 0.1, "height": 0.12, "density": 400},
    "tentacles": {"count": 6, "links": 4, "link_length": 0.06, "link_radius": 0.02},
}


def level(at: tuple[float, float] = (-1.2, 0.0), rival_at: tuple[float, float] = (0.0, 2.5),
          **game: Any) -> dict[str, Any]:  # fmt: skip
    """The flag at the origin (radius 0.5); the runner "you" `at`, the rival "other"
    `rival_at`; `game` changes the rules."""
    rules: dict[str, Any] = {
        "mode": "race",
        "runner": "you",
        "flag": {"position": [0.0, 0.0], "radius": 0.5},
        "seconds": 20,
    }
    rules.update(game)
    creatures = [
        {"name": "you", "position": list(at), **copy.deepcopy(CREATURE)},
        {"name": "other", "position": list(rival_at), **copy.deepcopy(CREATURE)},
    ]
    return {
        "version": 1,
        "name": "test race",
        "seed": 5,
        "plugins": {"fur": False, "race": {}},
        "game": rules,
        "creatures": creatures,
    }
