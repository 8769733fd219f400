"""`Settings`: a world's fixed-step clock and physics constants.

Their defaults are read from the core scene schema's `physics` properties
(`assets/schema/core.schema.json`), the one place they are written, so a world built
without a scene (`World()`) runs with the same constants as a scene that leaves
`physics` out. `BUILD_ONLY` are the `physics` keys used while a scene is built, not
while it runs.
"""

from __future__ import annotations

import importlib.resources
import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

BUILD_ONLY = ("separate_overlaps",)  # read by scene validation, not kept in Settings


def physics_defaults() -> dict[str, Any]:
    """The `physics` defaults of the core scene schema, by key."""
    schema = importlib.resources.files("ecs_tentacles.assets") / "schema" / "core.schema.json"
    physics = json.loads(schema.read_text(encoding="utf-8"))["properties"]["physics"]
    return {key: spec["default"] for key, spec in physics["properties"].items()}


_DEFAULT = physics_defaults()


@dataclass(frozen=True)
class Settings:
    """The fixed-step clock and physics constants of a world (a scene's `physics`)."""

    fps: float = float(_DEFAULT["fps"])
    substeps: int = int(_DEFAULT["substeps"])
    gravity: tuple[float, float, float] = tuple(float(g) for g in _DEFAULT["gravity"])  # type: ignore[assignment]
    ground_friction: float = float(_DEFAULT["ground_friction"])
    sucker_timeconst: float = float(_DEFAULT["sucker_timeconst"])
    max_speed: float = float(_DEFAULT["max_speed"])  # m/s: faster has blown up (physics/health.py)
    max_penetration: float = float(_DEFAULT["max_penetration"])  # m: deeper has blown up
    sleep: bool = bool(_DEFAULT["sleep"])  # still, idle creatures are not stepped (physics/sleep)

    @classmethod
    def from_physics(cls, physics: Mapping[str, Any]) -> Settings:
        """The settings of a scene's `physics` object (defaults filled in)."""
        return cls(
            fps=float(physics["fps"]),
            substeps=int(physics["substeps"]),
            gravity=tuple(float(g) for g in physics["gravity"]),  # type: ignore[arg-type]
            ground_friction=float(physics["ground_friction"]),
            sucker_timeconst=float(physics["sucker_timeconst"]),
            max_speed=float(physics["max_speed"]),
            max_penetration=float(physics["max_penetration"]),
            sleep=bool(physics["sleep"]),
        )

    @property
    def dt(self) -> float:
        """Seconds per frame."""
        return 1.0 / self.fps

    @property
    def substep_dt(self) -> float:
        """Seconds per physics step (the MuJoCo timestep)."""
        return 1.0 / (self.fps * self.substeps)
