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
from dataclasses import dataclass
from typing import cast

from ecs_tentacles.scene.scene_spec import LodSpec, PhysicsSpec

BUILD_ONLY = ("separate_overlaps",)  # read by scene validation, not kept in Settings


def physics_defaults() -> PhysicsSpec:
    """The `physics` defaults of the core scene schema, by key (every key has one)."""
    schema = importlib.resources.files("ecs_tentacles.assets") / "schema" / "core.schema.json"
    physics = json.loads(schema.read_text(encoding="utf-8"))["properties"]["physics"]
    return cast(PhysicsSpec, {key: spec["default"] for key, spec in physics["properties"].items()})


_DEFAULT = physics_defaults()


@dataclass(frozen=True)
class LodSettings:
    """A scene's `physics.lod`: level-of-detail budgets (`ecs_tentacles.physics.lod`)."""

    enabled: bool = bool(_DEFAULT["lod"]["enabled"])
    full: int = int(_DEFAULT["lod"]["full"])
    reduced: int = int(_DEFAULT["lod"]["reduced"])
    hold_seconds: float = float(_DEFAULT["lod"]["hold_seconds"])
    contact_margin: float = float(_DEFAULT["lod"]["contact_margin"])
    focus: tuple[float, float, float] | None = None  # x, y, radius (m): always full inside

    @classmethod
    def from_json(cls, lod: LodSpec) -> LodSettings:
        defaults = cls()
        return cls(
            enabled=bool(lod.get("enabled", defaults.enabled)),
            full=int(lod.get("full", defaults.full)),
            reduced=int(lod.get("reduced", defaults.reduced)),
            hold_seconds=float(lod.get("hold_seconds", defaults.hold_seconds)),
            contact_margin=float(lod.get("contact_margin", defaults.contact_margin)),
            focus=(float(focus["center"][0]), float(focus["center"][1]), float(focus["radius"]))
            if (focus := lod.get("focus"))
            else None,
        )


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
    lod: LodSettings = LodSettings()  # level of detail (physics/lod)

    @classmethod
    def from_physics(cls, physics: PhysicsSpec) -> Settings:
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
            lod=LodSettings.from_json(physics.get("lod", {})),
        )

    @property
    def dt(self) -> float:
        """Seconds per frame."""
        return 1.0 / self.fps

    @property
    def substep_dt(self) -> float:
        """Seconds per physics step (the MuJoCo timestep)."""
        return 1.0 / (self.fps * self.substeps)
