"""Pairs of creatures near each other: `near_pairs` (the test), `NearPairCache` (the
same answers, kept from one call to the next while nothing moved far: a Verlet list) and
`nearest_gap` (each creature's smallest gap among the pairs the proxies measured).

    a, b = near_pairs(centre, radius, margin)  # spheres within margin of each other
    pairs = NearPairCache(slack=0.25)
    a, b = pairs(centre, radius, margin)  # what near_pairs(centre, radius, margin) gives
    near = nearest_gap(count, a, b, gaps)  # gaps: `ContactProxies.pair_gaps`'s

A large crowd's pairs come from a k-d tree, built and queried on every call: at 10,000
creatures about 3 ms each, and a frame asks several times (the level of detail, the
proxies and their refreshes within the frame, crowd avoidance). The cache asks the tree
once for the pairs within `margin + slack` and keeps them while every sphere has moved
(centre) and grown (radius) by less than half the slack since: a pair can only have come
within `margin` if it was within `margin + slack` then. Each call filters the kept pairs
with near_pairs's own test, so the answer is the same pairs in the same order; the tree
is asked again only when some creature travelled far. Crowds small enough for the dense
comparison are not cached (it is cheap, and it stays the one code path they take).
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels

SLACK = 0.25  # metres of extra reach the kept pairs are found with
DENSE_PAIRS = 32  # creatures up to which every pair is compared (no tree to build)
_NONE = np.zeros(0, dtype=np.int64)
_EVERY = np.zeros(0, dtype=np.bool_)  # `kept_within`'s "every creature"
KERNELS = OptionalKernels("ecs_tentacles.physics.kernels", "ECS_TENTACLES_SENSE")


class NearPairCache:
    """`near_pairs` for one caller's spheres, answered from pairs kept between calls."""

    def __init__(self, slack: float = SLACK):
        if not slack > 0:
            raise ValueError(f"slack: must be > 0, got {slack}")
        self.slack = slack
        self.queries = 0  # times the tree was asked (for benchmarks and tests)
        self._kept: tuple[np.ndarray, np.ndarray] | None = None
        self._centre = np.zeros((0, 3))
        self._radius = np.zeros(0)
        self._reach = 0.0
        self._offsets = np.zeros(1, dtype=np.int64)  # creature c's kept pairs: [c, c + 1)

    def __call__(
        self, centre: np.ndarray, radius: np.ndarray, margin: float, among: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """`near_pairs(centre, radius, margin)`; with `among` ((n,) bool), only its pairs
        whose first creature is among them (the same pairs in the same order: the
        proxies ask for the stepped creatures' pairs, a few of a replayed crowd's)."""
        if len(centre) <= DENSE_PAIRS:
            a, b = near_pairs(centre, radius, margin)
            if among is not None:
                first = among[a]
                a, b = a[first], b[first]
            return a, b
        if not self._still_valid(centre, radius, margin):
            reach = margin + self.slack
            self._kept = near_pairs(centre, radius, reach)
            self._offsets = np.searchsorted(self._kept[0], np.arange(len(centre) + 1))
            self._centre, self._radius, self._reach = centre.copy(), radius.copy(), reach
            self.queries += 1
        assert self._kept is not None
        a, b = self._kept
        fast = KERNELS.get()
        if fast is not None:  # the same pairs in one pass (no index arrays)
            every = _EVERY if among is None else np.asarray(among, dtype=np.bool_)
            found_a, found_b = fast.kept_within(
                centre, radius, a, b, self._offsets, every, float(margin)
            )
            return np.asarray(found_a), np.asarray(found_b)
        if among is not None:  # the kept pairs are sorted by a: each creature's are a run
            a, b = _runs_of(self._offsets, np.flatnonzero(among), a, b)
        keep = spheres_within(centre, radius, a, b, margin)
        return a[keep], b[keep]

    def _still_valid(self, centre: np.ndarray, radius: np.ndarray, margin: float) -> bool:
        if self._kept is None or self._centre.shape != centre.shape:
            return False
        fast = KERNELS.get()
        if fast is not None:  # one pass, no temporaries (called a few times a frame)
            most = float(fast.largest_move(centre, self._centre, radius, self._radius))
            return bool(margin + 2.0 * most < self._reach)  # NaN: never valid
        moved = np.linalg.norm(centre - self._centre, axis=1) + np.maximum(radius - self._radius, 0)
        return bool(margin + 2.0 * moved.max() < self._reach)  # NaN: never valid


def _runs_of(
    offsets: np.ndarray, creatures: np.ndarray, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (a, b) of `creatures` (ascending), each creature's run of pairs from
    `offsets[c]` to `offsets[c + 1]`, in order."""
    first, end = offsets[creatures], offsets[creatures + 1]
    per = end - first
    total = int(per.sum())
    if total == len(a):
        return a, b
    index = np.arange(total) - np.repeat(np.cumsum(per) - per - first, per)
    return a[index], b[index]


def spheres_within(
    centre: np.ndarray, radius: np.ndarray, a: np.ndarray, b: np.ndarray, margin: float
) -> np.ndarray:
    """(pairs,) bool: spheres a[p] and b[p] come within `margin` of each other (the numba
    kernel when numba is installed: the same numbers, without a pass per operation)."""
    fast = KERNELS.get()
    if fast is not None:
        ia, ib = np.asarray(a, np.int64), np.asarray(b, np.int64)  # no copy when they are
        return np.asarray(fast.spheres_within(centre, radius, ia, ib, float(margin)))
    gap = np.linalg.norm(centre[a] - centre[b], axis=1) - (radius[a] + radius[b])
    return np.asarray(gap < margin)


def near_pairs(
    centre: np.ndarray, radius: np.ndarray, margin: float
) -> tuple[np.ndarray, np.ndarray]:
    """Ordered pairs (a, b), a != b, whose spheres come within `margin` of each other,
    sorted by a then b. Small crowds compare every pair; large ones ask a k-d tree for
    the candidates (linear in creatures, not quadratic) and keep the same test."""
    n = len(centre)
    if n > DENSE_PAIRS:
        from scipy.spatial import cKDTree  # here: scipy.spatial costs 0.25 s to import

        tree = cKDTree(centre)
        i, j = tree.query_pairs(2.0 * float(radius.max()) + margin, output_type="ndarray").T
        keep = spheres_within(centre, radius, i, j, margin)
        a = np.concatenate((i[keep], j[keep]))
        b = np.concatenate((j[keep], i[keep]))
        order = np.lexsort((b, a))
        return a[order].astype(np.int64), b[order].astype(np.int64)
    fast = KERNELS.get()
    if fast is not None:  # the same pairs without a pass per operation (40 -> 2 us at 16)
        a, b = fast.dense_pairs(
            np.asarray(centre, np.float64), np.asarray(radius, np.float64), float(margin)
        )
        return np.asarray(a), np.asarray(b)
    found_a, found_b = [], []
    block = max(1, 4_000_000 // max(n, 1))  # bound the (block, n) distance matrix
    for lo in range(0, n, block):
        hi = min(n, lo + block)
        apart = centre[lo:hi, None, :] - centre[None, :, :]
        gap = np.sqrt(np.add.reduce(apart * apart, axis=2))  # `np.linalg.norm`'s numbers
        gap -= radius[lo:hi, None] + radius[None, :]
        near = gap < margin
        near.reshape(-1)[lo :: n + 1] = False  # each sphere and itself: (i, lo + i)
        ia, ib = np.nonzero(near)
        found_a.append(ia + lo)
        found_b.append(ib)
    if not found_a:
        return _NONE, _NONE
    return np.concatenate(found_a), np.concatenate(found_b)


def nearest_gap(
    count: int, a: np.ndarray, b: np.ndarray, gaps: np.ndarray, among: np.ndarray | None = None
) -> np.ndarray:
    """(count,) each creature's smallest gap of the pairs (`ContactProxies.pair_gaps`),
    counting only partners in `among` ((count,) bool) when given; inf where none."""
    near = np.full(count, np.inf)
    if among is None:
        np.minimum.at(near, a, gaps)
        np.minimum.at(near, b, gaps)
    else:
        to_b, to_a = among[b], among[a]
        np.minimum.at(near, a[to_b], gaps[to_b])
        np.minimum.at(near, b[to_a], gaps[to_a])
    return near
