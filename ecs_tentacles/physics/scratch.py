"""A stepping thread's scratch: its copy of a batch's model (the per-row overlay is
written into it) and its one MjData, with the warning counters the health check reads
(`ecs_tentacles.physics.batch`: thread k always steps on scratch k)."""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np


@dataclass
class Scratch:
    """One stepping thread's copy of a batch's model and its one MjData."""

    model: mujoco.MjModel
    data: mujoco.MjData
    forced: bool = False  # applied forces were written into `data` (zero them next time)
    warnings: np.ndarray = field(init=False)  # `data.warning.number`, looked up once
    no_warnings: bytes = field(init=False)  # its bytes when nothing was raised
    xpos: np.ndarray = field(init=False)  # `data.xpos` and `data.xquat`, looked up once
    xquat: np.ndarray = field(init=False)  # (views of MjData's buffer: they never move)

    def __post_init__(self) -> None:
        self.warnings = self.data.warning.number
        self.no_warnings = bytes(self.warnings.nbytes)
        self.xpos, self.xquat = self.data.xpos, self.data.xquat
