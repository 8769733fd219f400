"""Fur presets from the thesis's table (Figure 3.1), kept in the scene schema.

The schema's ``$defs.fur["x-presets"]`` is the one place they are written, so a
scene's `fur.preset` fills exactly these values (then schema defaults) through
`ecs_tentacles.scene.defaults.with_defaults`; any field the scene gives wins.

- hedgehog: stiff quills along the back folding toward the rear; they lift and
  interlock (random twist); no dynamics.
- cat: fine hair of varying length folding toward the rear; lifts along neck, back
  and tail; some random; dynamic blend on.
- bird: feathers lying toward the body; they only lift, no other axis; no dynamics.
"""

from __future__ import annotations

import copy
from typing import Any

from ecs_tentacles.scene.defaults import with_defaults
from ecs_tentacles.scene.schema import load_schema


def preset_names() -> list[str]:
    """The presets a scene can name (besides "none")."""
    return sorted(load_schema()["$defs"]["fur"]["x-presets"])


def preset(name: str) -> dict[str, Any]:
    """The fur fields preset `name` sets (a copy); KeyError lists the known names."""
    presets = load_schema()["$defs"]["fur"]["x-presets"]
    if name not in presets:
        raise KeyError(f"no fur preset {name!r}; known: {', '.join(sorted(presets))}")
    return copy.deepcopy(presets[name])


def resolve(fur: dict[str, Any]) -> dict[str, Any]:
    """A `fur` scene object with its preset and then the schema defaults filled in."""
    scene = with_defaults({"version": 1, "creatures": [{"fur": fur}]})
    resolved: dict[str, object] = scene["creatures"][0]["fur"]
    return resolved
