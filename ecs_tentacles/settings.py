"""A world's settings: the fixed-step clock and the physics constants.

Core: imports nothing of the engine, so the physics package and the World both use it.
`World.from_scene` fills it from the scene's `physics` block; `ecs_tentacles.world`
re-exports it (`from ecs_tentacles.world import Settings` keeps working).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Settings:
    """The fixed-step clock and physics constants of a world."""

    fps: float = 60.0
    substeps: int = 8
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    ground_friction: float = 1.0
    sucker_timeconst: float = 0.005
    max_speed: float = 12.0  # m/s: a body faster than this has blown up (physics/health.py)
    max_penetration: float = 0.05  # m: a contact deeper than this has blown up
    sleep: bool = True  # still, idle creatures are not stepped (physics/sleep.py)

    @property
    def dt(self) -> float:
        """Seconds per frame."""
        return 1.0 / self.fps

    @property
    def substep_dt(self) -> float:
        """Seconds per physics step (the MuJoCo timestep)."""
        return 1.0 / (self.fps * self.substeps)
