"""Levels of detail of a creature's physics (`PhysicsBackend.tier`, one per creature).

* `FULL`: the creature's model at the scene's physics rate, every contact.
* `REDUCED`: a cheaper model of the creature (`physics.reduced`: about half the links,
  a quarter of the rate, `reduced_substeps`), shown as the full creature; a move
  between FULL and REDUCED fits one model's state to the other's.
* `KINEMATIC`: not stepped; its poses are written from outside (gait clips,
  `ecs_tentacles.clips`) and its state row is set when it is promoted again.

Which creature is at which tier is decided elsewhere (`ecs_tentacles.clips`); the
backend only steps each tier as it says.
"""

from __future__ import annotations

FULL, REDUCED, KINEMATIC = 0, 1, 2
NAMES = ("full", "reduced", "kinematic")


REDUCED_RATE = 4  # a FULL creature takes this many steps for one of a REDUCED one


def reduced_substeps(substeps: int) -> int:
    """Steps a REDUCED creature takes per frame where a FULL one takes `substeps`: a
    quarter, rounded up (120 Hz at the default 480 Hz)."""
    return max(1, -(-substeps // REDUCED_RATE))
