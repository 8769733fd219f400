"""Levels of detail of a creature's physics (`PhysicsBackend.tier`, one per creature).

* `FULL`: the creature's model at the scene's physics rate, every contact.
* `REDUCED`: a cheaper model of the creature (`physics.reduced`: about half the links,
  an eighth of the rate, `reduced_substeps`), shown as the full creature; a move
  between FULL and REDUCED fits one model's state to the other's.
* `KINEMATIC`: not stepped; its poses are written from outside (gait clips,
  `ecs_tentacles.clips`) and its state row is set when it is promoted again.

Which creature is at which tier is decided elsewhere (`ecs_tentacles.clips`); the
backend only steps each tier as it says.
"""

from __future__ import annotations

FULL, REDUCED, KINEMATIC = 0, 1, 2
NAMES = ("full", "reduced", "kinematic")


# A FULL creature takes this many steps for one of a REDUCED one: at the default 480 Hz
# a reduced creature takes one step a frame (60 Hz), which halves its MuJoCo time against
# 120 Hz with the crowd's progress and contacts held (docs/crowds.md, "Levels of detail").
REDUCED_RATE = 8


def reduced_substeps(substeps: int) -> int:
    """Steps a REDUCED creature takes per frame where a FULL one takes `substeps`: an
    eighth, rounded up (60 Hz, one step a frame, at the default 480 Hz)."""
    return max(1, -(-substeps // REDUCED_RATE))
