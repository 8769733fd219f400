"""The nearest guide roots of points, for child hairs (`ecs_tentacles.fur.children`).

`nearest(points, roots, k)` -> for each point, the indices of its `k` nearest roots,
nearest first, and their squared distances. Exact and deterministic: distances are
numpy's `sum((point - root) ** 2)` and a tie goes to the lower root index. A k-d tree
(`scipy.spatial.cKDTree`) over the distinct roots finds a few candidates per point,
in chunks of `CHUNK` points: time about (points + roots) log(roots), memory linear in
both (a brute force took points x roots of both). Roots at one spot are one tree entry
(their k lowest indices); a point whose candidates may miss a tie (several distinct
roots at an equal distance, to the last bit) takes every root within that distance.
"""

from __future__ import annotations

import numpy as np

CHUNK = 65_536  # points queried at once: under 1 KB each of temporaries
SPARE = 2  # distinct roots asked of the tree beyond `k`: room for near ties
SLACK = 1e-9  # relative: the tree's distances and numpy's differ in the last bits


def nearest(points: np.ndarray, roots: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(indices (n, k) int64, squared distances (n, k)) of the `k` nearest `roots` of
    each of `points` (both (.., 3) float64), nearest first, ties to the lower index.
    Needs k <= len(roots)."""
    if not 0 < k <= len(roots):
        raise ValueError(f"k must be in [1, {len(roots)}], got {k}")
    spots, first, inverse = np.unique(roots, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    # the lowest k root indices of each spot (-1 where a spot has fewer)
    order = np.argsort(inverse, kind="stable")
    start = np.searchsorted(inverse[order], np.arange(len(spots)))
    count = np.diff(np.append(start, len(order)))
    members = np.full((len(spots), k), -1, np.int64)
    for j in range(k):
        has = count > j
        members[has, j] = order[start[has] + j]
    from scipy.spatial import cKDTree  # here: scipy.spatial costs 0.25 s to import

    tree = cKDTree(spots)
    asked = min(k + SPARE, len(spots))
    rows = np.empty((len(points), k), np.int64)
    d2 = np.empty((len(points), k))
    for at in range(0, len(points), CHUNK):
        part = points[at : at + CHUNK]
        distance, candidates = tree.query(part, asked)
        candidates = candidates.reshape(len(part), asked)
        rows[at : at + len(part)], d2[at : at + len(part)] = _pick(
            part, roots, candidates, members, first, k
        )
        # complete when no spot outside the candidates can come as near as the k-th root
        if asked < len(spots):
            last = np.sqrt(d2[at : at + len(part), -1])
            beyond = distance.reshape(len(part), asked)[:, -1]
            doubt = np.flatnonzero(beyond <= last * (1.0 + SLACK) + 1e-12)
            for i in doubt.tolist():
                near = tree.query_ball_point(part[i], last[i] * (1.0 + SLACK) + 1e-12)
                rows[at + i], d2[at + i] = _pick(
                    part[i : i + 1], roots, np.asarray([near]), members, first, k
                )
    return rows, d2


def _pick(
    points: np.ndarray,
    roots: np.ndarray,
    candidates: np.ndarray,
    members: np.ndarray,
    first: np.ndarray,
    k: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The k nearest roots among those of the candidate spots (n, c) of each point, by
    (exact squared distance, index), with those distances."""
    d2 = np.sum((points[:, None, :] - roots[first[candidates]]) ** 2, axis=2)
    rows = members[candidates].reshape(len(points), -1)  # each spot's first k roots
    d2 = np.where(rows < 0, np.inf, np.repeat(d2, k, axis=1))
    ranked = np.lexsort((rows, d2), axis=-1)[:, :k]
    return np.take_along_axis(rows, ranked, axis=1), np.take_along_axis(d2, ranked, axis=1)
