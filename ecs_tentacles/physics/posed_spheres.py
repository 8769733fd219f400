"""Reach spheres found as poses are written: `PosedSpheres`, where a writer of creatures'
poses (the replay, `clips.replay`) leaves each creature's bounding sphere for the next
frame's `ContactProxies.sense`, which then reads the Transform store only for the others.
Writes nothing itself: the writer fills it, `sense` reads it and makes the next one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PosedSpheres:
    """Reach spheres found by whoever wrote creatures' poses (`ContactProxies.posed_spheres`),
    for the next frame's `sense`: creature c's at `centre[c]`, `radius[c]` where `known[c]`.
    `start` and `rbound` are the proxies' (creature c's body b is `start[c] + b`)."""

    start: np.ndarray
    rbound: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    known: np.ndarray

    @classmethod
    def empty(cls, start: np.ndarray, rbound: np.ndarray) -> PosedSpheres:
        count = len(start)
        known = np.zeros(count, dtype=bool)
        return cls(start, rbound, np.empty((count, 3)), np.empty(count), known)
