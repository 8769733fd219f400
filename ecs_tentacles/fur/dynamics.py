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
With numba (the rig's kernels) a strand kernel does the same float32 operations in
the same order guide by guide; numpy is the fallback and gives the same result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ecs_tentacles.fur import rig as rig_math

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
    fresh: np.ndarray | None = None  # strands not stepped yet

    def _state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.pos is None or self.prev is None or self.fresh is None:
            points = len(self.segment)
            self.pos = np.zeros((points, 3, len(self.guides)), dtype=F32)
            self.prev = np.zeros_like(self.pos)
            self.fresh = np.ones(len(self.guides), dtype=bool)
        return self.pos, self.prev, self.fresh

    def subset(self, cols: np.ndarray) -> Strands:
        """The strands `cols` (indices, ascending) as Strands of their own: their settings
        and state copied (`put` writes the state back). Each strand steps alone, so a
        subset's step gives its strands the bits the whole step gives them."""
        pos, prev, fresh = self._state()
        return Strands(
            guides=self.guides[cols],
            segment=np.ascontiguousarray(self.segment[:, cols]),
            pull=self.pull[cols],
            keep=self.keep[cols],
            gravity=np.ascontiguousarray(self.gravity[:, cols]),
            profile=self.profile,
            pos=np.ascontiguousarray(pos[..., cols]),
            prev=np.ascontiguousarray(prev[..., cols]),
            fresh=fresh[cols],
        )

    def put(self, cols: np.ndarray, part: Strands) -> None:
        """Write back the state of `part`, the `subset(cols)` that stepped."""
        pos, prev, fresh = self._state()
        assert part.pos is not None and part.prev is not None and part.fresh is not None
        pos[..., cols], prev[..., cols], fresh[cols] = part.pos, part.prev, part.fresh

    def step_kernel(
        self,
        curves: np.ndarray,
        frames: np.ndarray,
        normal: np.ndarray,
        weight: np.ndarray,
        parallel: bool = False,
    ) -> bool:
        """`step` for every strand by numba's kernel, in place in `curves` (n, points, 3).

        `frames` (n, 4, 3) give the roots, `normal` and `weight` are the strands' (3, m)
        and (m,). `parallel`: on all cores (large furs, `rig.use_parallel`). Returns
        False, doing nothing, when the kernels are not there (then call `step`).
        """
        k = rig_math.kernels()
        if k is None:
            return False
        pos, prev, fresh = self._state()
        step, lock = rig_math.kernel(k, "strands", parallel)
        with lock:
            step(
                pos, prev, fresh, curves, frames, self.guides, normal, weight,
                self.keep, self.pull, self.gravity, self.segment, self.profile.reshape(-1),
            )  # fmt: skip
        return True

    def step(
        self,
        rig: np.ndarray,
        root: np.ndarray,
        normal: np.ndarray,
        weight: np.ndarray,
        cols: slice | None = None,
    ) -> np.ndarray:
        """Advance one frame toward `rig` (points, 3, m); return the blended curves.

        `root` and `normal` (3, m) are world space; `weight` (m,) is each guide's
        dynamic blend (0 shows the rig exactly). With `cols`, only those strands step
        (the arrays given are theirs): callers go block by block to stay in cache.
        """
        cols = slice(None) if cols is None else cols
        pos, prev, fresh = self._state()
        pos, prev = pos[..., cols], prev[..., cols]
        fresh = fresh[cols]
        if fresh.any():  # first frame of these strands: start at rest on the rig
            pos[..., fresh] = rig[..., fresh]
            prev[..., fresh] = rig[..., fresh]
            fresh[...] = False
        velocity = pos - prev
        velocity *= self.keep[cols]
        prev[...] = pos
        pos += velocity
        pos += self.gravity[:, cols]
        pull = rig - pos
        pull *= self.pull[cols]
        pos += pull
        pos[0] = rig[0]
        segment = self.segment[:, cols]
        for k in range(1, len(pos)):  # follow the leader, a few points per guide
            link = pos[k] - pos[k - 1]
            length = np.sqrt(link[0] * link[0] + link[1] * link[1] + link[2] * link[2])
            link *= segment[k] / np.maximum(length, 1e-12)
            np.add(pos[k - 1], link, out=pos[k])
            below = (pos[k, 0] - root[0]) * normal[0]
            below += (pos[k, 1] - root[1]) * normal[1]
            below += (pos[k, 2] - root[2]) * normal[2]
            np.minimum(below, 0.0, out=below)
            pos[k] -= below * normal
        result: np.ndarray = pos - rig
        result *= self.profile * weight
        result += rig
        return result
