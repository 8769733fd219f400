"""`Director`: what the director's tools hold between frames (a world resource).

The panel (`director.panel`) writes it from the mouse; the grab system
(`director/systems/grab.py`) and the plugin's drawing read it.
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.director.grab import Grab


class Director:
    """`world.resource(Director)`: what the director's tools hold between frames."""

    provided_by = "director"

    def __init__(self) -> None:
        self.grab: Grab | None = None
        self.brush: tuple[np.ndarray, float] | None = None  # centre (3,), radius (m)
