"""Dynamic blend: a light strand simulation the guide's tip follows (thesis 3.2, cat).

Each dynamic guide's points are simulated in world space (Verlet: inertia with
damping, gravity, a spring pulling every point back to the rig's pose), its root
pinned to the rig and its segment lengths restored by follow-the-leader from the
root out; no point goes below the skin's tangent plane at the root. The shown
curve blends rig and strand along the guide: ``rig + profile * dynamic * (sim - rig)``
with `profile` 0 at the root and 1 at the tip, so the root follows the rig and the
tip the strand. The body's own motion drives the strand, since the rig pose moves
with the body and the simulated points lag behind it.

Arrays are float32 and laid out (points, 3, n) so each step is a contiguous operation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

F32 = np.float32


def blend_profile(points: int) -> np.ndarray:
    """Weight of the strand along a guide: smoothstep from 0 at the root to 1 at the tip."""
    u = np.linspace(0.0, 1.0, points)
    return (u * u * (3.0 - 2.0 * u)).astype(F32)


@dataclass
class Strands:
    """State of m simulated guides: points and previous points (points, 3, m)."""

    guides: np.ndarray  # (m,) guide rows
    segment: np.ndarray  # (points, m) rest segment lengths (segment[0] = 0)
    pull: np.ndarray  # (m,) per-step fraction pulled back to the rig, from stiffness
    keep: np.ndarray  # (m,) per-step fraction of velocity kept, from damping
    gravity: np.ndarray  # (3, m) gravity * dt^2 per step
    profile: np.ndarray  # (points, 1, 1)
    pos: np.ndarray | None = None
    prev: np.ndarray | None = None

    def step(
        self, rig: np.ndarray, root: np.ndarray, normal: np.ndarray, weight: np.ndarray
    ) -> np.ndarray:
        """Advance one frame toward `rig` (points, 3, m); return the blended curves.

        `root` and `normal` (3, m) are world space; `weight` (m,) is each guide's
        dynamic blend (0 shows the rig exactly).
        """
        if self.pos is None or self.prev is None or self.pos.shape != rig.shape:
            self.pos = rig.copy()
            self.prev = rig.copy()
        pos, prev = self.pos, self.prev
        velocity = (pos - prev) * self.keep
        prev[...] = pos
        pos += velocity
        pos += self.gravity
        pos += (rig - pos) * self.pull
        pos[0] = rig[0]
        for k in range(1, len(pos)):  # follow the leader, a few points per guide
            link = pos[k] - pos[k - 1]
            length = np.sqrt(link[0] * link[0] + link[1] * link[1] + link[2] * link[2])
            pos[k] = pos[k - 1] + link * (self.segment[k] / np.maximum(length, 1e-12))
            below = (pos[k, 0] - root[0]) * normal[0]
            below += (pos[k, 1] - root[1]) * normal[1]
            below += (pos[k, 2] - root[2]) * normal[2]
            pos[k] -= np.minimum(below, 0.0) * normal
        result: np.ndarray = rig + (self.profile * weight) * (pos - rig)
        return result
