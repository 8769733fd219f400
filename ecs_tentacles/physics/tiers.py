"""Levels of detail of a creature's physics (`PhysicsBackend.tier`, one per creature).

* `FULL`: the creature's model at the scene's physics rate, every contact.
* `REDUCED`: the same bodies, joints and servos (the same state, so a move between
  FULL and REDUCED is exact) stepped at half the rate (`reduced_substeps`).
* `KINEMATIC`: not stepped; its poses are written from outside (gait clips,
  `ecs_tentacles.lod`) and its state row is set when it is promoted again.

Which creature is at which tier is decided elsewhere (`ecs_tentacles.lod`); the
backend only steps each tier as it says.
"""

from __future__ import annotations

FULL, REDUCED, KINEMATIC = 0, 1, 2
NAMES = ("full", "reduced", "kinematic")


def reduced_substeps(substeps: int) -> int:
    """Steps a REDUCED creature takes per frame where a FULL one takes `substeps`."""
    return max(1, substeps // 2)
