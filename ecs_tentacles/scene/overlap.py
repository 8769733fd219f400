"""Overlap of creatures' bodies at build, measured on their capsules; moving them apart.

Every body is a capsule (`CreatureLayout.capsules`: the mantle around its axis, every
link as built). Two creatures overlap when any capsule of one is closer to a capsule of
the other than the sum of their radii. Candidate pairs come from a sweep over the
creatures' bounding boxes; each pair's capsules are compared all against all in one
vectorised call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Creatures pushed apart keep this gap (m) between their reaches.
CLEARANCE = 0.02
# Rounds of pushing before giving up on a crowd that keeps overlapping.
ROUNDS = 64


@dataclass(frozen=True)
class Overlap:
    """Creature `later` overlaps creature `earlier` by `depth` metres at build."""

    earlier: int
    later: int
    depth: float
    what: str  # "mantles", "tentacles" or "a tentacle and a mantle"


def segment_distances(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Distances between segments p1-q1 and p2-q2 (arrays of (..., 3) that broadcast).

    The closest points of two segments (Ericson, Real-Time Collision Detection 5.1.9),
    for segments of non-zero length.
    """
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.maximum(np.einsum("...i,...i", d1, d1), 1e-300)
    e = np.maximum(np.einsum("...i,...i", d2, d2), 1e-300)
    b = np.einsum("...i,...i", d1, d2)
    c = np.einsum("...i,...i", d1, r)
    f = np.einsum("...i,...i", d2, r)
    denom = a * e - b * b
    parallel = denom <= 1e-12 * a * e
    s = np.where(parallel, 0.0, np.clip((b * f - c * e) / np.where(parallel, 1.0, denom), 0, 1))
    t = (b * s + f) / e
    s = np.where(t < 0.0, np.clip(-c / a, 0, 1), np.where(t > 1.0, np.clip((b - c) / a, 0, 1), s))
    t = np.clip(t, 0.0, 1.0)
    gap = (p1 + d1 * s[..., None]) - (p2 + d2 * t[..., None])
    return np.asarray(np.sqrt(np.einsum("...i,...i", gap, gap)))


@dataclass
class Bodies:
    """The capsules of one creature (row 0 is the mantle)."""

    starts: np.ndarray
    ends: np.ndarray
    radii: np.ndarray

    def box(self) -> np.ndarray:
        """Bounding box (2, 3): lowest and highest corner."""
        r = self.radii[:, None]
        low = np.minimum(self.starts, self.ends) - r
        high = np.maximum(self.starts, self.ends) + r
        return np.stack([low.min(axis=0), high.max(axis=0)])

    def reach(self) -> float:
        """Horizontal distance from the mantle's axis to the farthest capsule surface."""
        axis = self.starts[0, :2]
        ends = np.concatenate([self.starts[:, :2], self.ends[:, :2]]) - axis
        radii = np.concatenate([self.radii, self.radii])
        return float((np.hypot(ends[:, 0], ends[:, 1]) + radii).max())

    def moved(self, offset: np.ndarray) -> Bodies:
        return Bodies(self.starts + offset, self.ends + offset, self.radii)


def candidate_pairs(bodies: list[Bodies]) -> list[tuple[int, int]]:
    """Pairs (i < j) whose bounding boxes touch: a sweep along x, boxes checked on y, z."""
    if len(bodies) < 2:
        return []
    boxes = np.stack([b.box() for b in bodies])  # (n, 2, 3)
    order = np.argsort(boxes[:, 0, 0], kind="stable")
    lows = boxes[order, 0, 0]
    pairs: list[tuple[int, int]] = []
    for rank, i in enumerate(order):
        stop = int(np.searchsorted(lows, boxes[i, 1, 0], side="right"))
        others = order[rank + 1 : stop]
        if not len(others):
            continue
        low, high = boxes[others, 0], boxes[others, 1]
        touch = np.all((low[:, 1:] <= boxes[i, 1, 1:]) & (high[:, 1:] >= boxes[i, 0, 1:]), axis=1)
        pairs.extend((min(int(i), j), max(int(i), j)) for j in others[touch].tolist())
    return sorted(pairs)


def _depth(a: Bodies, b: Bodies) -> tuple[float, str]:
    """Deepest interpenetration of two creatures' capsules and which parts it is between."""
    distance = segment_distances(
        a.starts[:, None], a.ends[:, None], b.starts[None, :], b.ends[None, :]
    )
    depth = a.radii[:, None] + b.radii[None, :] - distance
    i, j = np.unravel_index(int(np.argmax(depth)), depth.shape)
    what = {0: "tentacles", 1: "a tentacle and a mantle", 2: "mantles"}[int(i == 0) + int(j == 0)]
    return float(depth[i, j]), what


def find_overlaps(bodies: list[Bodies]) -> list[Overlap]:
    """Every pair of creatures whose capsules interpenetrate, in index order."""
    found = []
    for i, j in candidate_pairs(bodies):
        depth, what = _depth(bodies[i], bodies[j])
        if depth > 1e-9:
            found.append(Overlap(i, j, depth, what))
    return found


def separate(bodies: list[Bodies]) -> tuple[np.ndarray, list[Overlap]]:
    """Push later creatures away from earlier ones they overlap, sideways, until none do.

    A creature that overlaps an earlier one is moved straight away from it (along +x if
    their axes coincide) until their reaches no longer meet: tentacles laid straight
    out all round, plus `CLEARANCE`. Merely clearing the built bodies would leave the
    tentacles interleaved, and writhing tentacles that start interleaved touch in the
    first second. Creature 0 never moves. Returns each creature's offset (n, 3) and the
    overlaps left after `ROUNDS` rounds (empty when the crowd came apart).
    """
    offsets = np.zeros((len(bodies), 3))
    current = list(bodies)
    reach = [b.reach() for b in bodies]
    for _ in range(ROUNDS):
        overlaps = find_overlaps(current)
        if not overlaps:
            return offsets, []
        for overlap in overlaps:
            i, j = overlap.earlier, overlap.later
            away = current[j].starts[0] - current[i].starts[0]
            away[2] = 0.0
            distance = float(np.hypot(away[0], away[1]))
            direction = away / distance if distance > 1e-9 else np.array([1.0, 0.0, 0.0])
            step = direction * max(reach[i] + reach[j] + CLEARANCE - distance, CLEARANCE)
            offsets[j] += step
            current[j] = current[j].moved(step)
    return offsets, find_overlaps(current)
