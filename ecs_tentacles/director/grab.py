"""Grab and throw: a spring pulls one body of a creature toward the mouse.

As MuJoCo's `simulate` viewer perturbs a body (Ctrl + drag), the force on the grabbed
body is a critically damped spring toward the target point, scaled by the creature's
mass so every creature answers the same way:

    F = m (k (target - p) - c v),   k = (2 pi FREQUENCY)^2,  c = 2 sqrt(k)

and its size is capped at `m * MAX_ACCELERATION`, so a drag never accelerates a
creature harder than about 2.5 g: the physics health check (speeds, penetrations)
never has to step in. The target is where the mouse ray meets the plane through the
grab point facing the camera (dragging up the screen lifts the creature). Letting go
removes the force: the creature keeps the speed the spring gave it (a throw) and
falls. Suckers that hold on release when stretched, as locomotion's rules say. While
grabbed a creature runs full physics and never sleeps.

`Grab` is the state the director's panel sets from the mouse; the `grab` system
(`director/systems/grab.py`) applies the force before each physics step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FREQUENCY = 2.0  # Hz: how briskly the grabbed body follows the mouse
MAX_ACCELERATION = 25.0  # m/s^2 the spring gives the creature at most
STIFFNESS = (2.0 * np.pi * FREQUENCY) ** 2
DAMPING = 2.0 * np.sqrt(STIFFNESS)  # critical


def spring_force(
    position: np.ndarray, velocity: np.ndarray, target: np.ndarray, mass: float
) -> np.ndarray:
    """The force (3,) on a grabbed body of a creature of `mass` kg (module docstring)."""
    pull = mass * (STIFFNESS * (np.asarray(target) - position) - DAMPING * np.asarray(velocity))
    size = float(np.linalg.norm(pull))
    limit = mass * MAX_ACCELERATION
    capped: np.ndarray = pull * (limit / size) if size > limit else pull
    return capped


@dataclass
class Grab:
    """One creature held by the mouse: which body (index into its batch's bodies), the
    target the spring pulls toward, and the plane the mouse ray meets."""

    creature: int  # entity
    body: int  # index of the grabbed body among the creature's bodies (0: the mantle)
    target: np.ndarray  # (3,) world metres
    plane_point: np.ndarray  # (3,) the grab point
    plane_normal: np.ndarray  # (3,) toward the camera
    last: np.ndarray | None = None  # the body's position last frame (its speed)
    force: np.ndarray | None = None  # the force applied this frame, for drawing and tests

    def aim(self, origin: np.ndarray, direction: np.ndarray) -> None:
        """Point the spring at where the ray meets the grab plane (unchanged if parallel)."""
        across = float(np.dot(direction, self.plane_normal))
        if abs(across) < 1e-9:
            return
        t = float(np.dot(self.plane_point - origin, self.plane_normal)) / across
        if t > 0:
            self.target = origin + t * direction
