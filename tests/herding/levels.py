"""Small herding levels for the tests: quick to build and step."""

from __future__ import annotations

import copy
from typing import Any

CREATURE = {
    "mantle": {"radius": 0.1, "height": 0.12, "density": 400},
    "tentacles": {"count": 6, "links": 4, "link_length": 0.06, "link_radius": 0.02},
}


def level(**game: Any) -> dict[str, Any]:
    """Two small creatures 1.2 m apart on the plane, a pen east of them, the predator west."""
    rules: dict[str, Any] = {
        "mode": "herding",
        "pen": {"centre": [1.2, 0.0], "radius": 0.6},
        "need": 1,
        "seconds": 20,
        "predator": {"position": [-1.5, 0.0], "speed": 1.0},
    }
    rules.update(game)
    return {
        "version": 1,
        "name": "test level",
        "seed": 3,
        "plugins": {"herding": {}},
        "game": rules,
        "creatures": [
            {"name": "a", "position": [0.0, 0.0], **copy.deepcopy(CREATURE)},
            {"name": "b", "position": [0.0, 1.2], **copy.deepcopy(CREATURE)},
        ],
    }
