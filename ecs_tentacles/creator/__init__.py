"""The creature creator (thesis III.B, IV.A.2): `CreatureDesign` is its model.

`ecs-tentacles create ... --out scene.json` drives it from the command line; the
interactive window (`window`: a thin layer over the same model) needs the renderer.
"""

from __future__ import annotations

from ecs_tentacles.creator.design import SHAPE_KEYS, CreatureDesign, TentacleDesign
from ecs_tentacles.creator.limits import DesignError

__all__ = ["SHAPE_KEYS", "CreatureDesign", "DesignError", "TentacleDesign"]
