"""The locomotion feature's components: a goal on a creature's path."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(eq=False)
class Goal:
    """A place `owner` should reach: within `radius` of `position`; `order` in its path."""

    owner: int
    order: int
    position: np.ndarray
    radius: float
