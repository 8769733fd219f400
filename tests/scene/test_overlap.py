"""Capsule distances, overlapping pairs and separation, against brute force."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.scene.overlap import (
    CLEARANCE,
    Bodies,
    candidate_pairs,
    find_overlaps,
    segment_distances,
)
from ecs_tentacles.scene.overlap import separate as separate_bodies


def _brute(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> float:
    s = np.linspace(0.0, 1.0, 801)
    a = p1 + s[:, None] * (q1 - p1)
    b = p2 + s[:, None] * (q2 - p2)
    return float(np.sqrt(((a[:, None] - b[None]) ** 2).sum(-1)).min())


@pytest.mark.parametrize(
    ("p1", "q1", "p2", "q2", "expected"),
    [
        ([0, 0, 0], [1, 0, 0], [0.5, -1, 1], [0.5, 1, 1], 1.0),  # crossing above
        ([0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], 1.0),  # collinear, end to end
        ([0, 0, 0], [1, 0, 0], [0.2, 0.3, 0], [0.8, 0.3, 0], 0.3),  # parallel, overlapping
        ([0, 0, 0], [1, 0, 0], [1.3, 0.4, 0], [2, 1, 0], 0.5),  # end to end point
        ([0, 0, 0], [0, 0, 1], [0.3, -1, 0.5], [0.3, 1, 0.5], 0.3),  # the mantle axis case
    ],
)
def test_segment_distance_known_cases(
    p1: list[float], q1: list[float], p2: list[float], q2: list[float], expected: float
) -> None:
    got = segment_distances(*(np.array(v, dtype=float) for v in (p1, q1, p2, q2)))
    assert float(got) == pytest.approx(expected, abs=1e-12)


def test_segment_distances_match_brute_force_on_random_segments() -> None:
    rng = np.random.default_rng(7)
    p1, q1, p2, q2 = rng.uniform(-1, 1, size=(4, 60, 3))
    got = segment_distances(p1, q1, p2, q2)
    expected = [_brute(*segment) for segment in zip(p1, q1, p2, q2, strict=True)]
    assert_allclose(got, expected, atol=2e-3)  # brute force samples 801 points a segment
    assert np.all(got <= np.array(expected) + 1e-12)  # and the exact one is never above it


def _rod(x: float, y: float, length: float = 0.5, radius: float = 0.05) -> Bodies:
    """A 'creature': a mantle capsule at (x, y) and one link along +x."""
    base = np.array([x, y, 0.0])
    starts = np.array([base, base + [0.1, 0, 0]])
    ends = np.array([base + [0, 0, 0.2], base + [0.1 + length, 0, 0]])
    return Bodies(starts, ends, np.array([0.1, radius]))


def test_candidate_pairs_are_the_pairs_whose_boxes_touch() -> None:
    rng = np.random.default_rng(3)
    bodies = [_rod(*rng.uniform(-2, 2, size=2)) for _ in range(40)]
    boxes = [b.box() for b in bodies]
    touching = [
        (i, j)
        for i, j in itertools.combinations(range(len(bodies)), 2)
        if np.all(boxes[i][0] <= boxes[j][1]) and np.all(boxes[j][0] <= boxes[i][1])
    ]
    assert candidate_pairs(bodies) == touching
    assert len(touching) > 10


def test_overlaps_name_the_deepest_parts() -> None:
    overlaps = find_overlaps([_rod(0, 0), _rod(0.4, 0.05), _rod(5, 5), _rod(0.08, 0.12)])
    assert [(o.earlier, o.later) for o in overlaps] == [(0, 1), (0, 3), (1, 3)]
    deepest = {(o.earlier, o.later): (round(o.depth, 6), o.what) for o in overlaps}
    # rod 1's mantle stands on rod 0's link, 0.05 from its axis: 0.1 + 0.05 - 0.05
    assert deepest[(0, 1)] == (0.1, "a tentacle and a mantle")
    # rods 0 and 3: mantles 0.144 apart (radii 0.1 + 0.1)
    assert deepest[(0, 3)] == (round(0.2 - np.hypot(0.08, 0.12), 6), "mantles")


def test_separation_clears_every_overlap_and_never_moves_the_first() -> None:
    bodies = [_rod(0, 0), _rod(0.1, 0.0), _rod(0.1, 0.1), _rod(0.0, 0.05), _rod(4, 4)]
    offsets, left = separate_bodies(bodies)
    assert left == []
    assert_allclose(offsets[0], 0.0)
    assert_allclose(offsets[4], 0.0)  # overlapped nobody
    assert_allclose(offsets[:, 2], 0.0)  # sideways only
    moved = [b.moved(o) for b, o in zip(bodies, offsets, strict=True)]
    assert find_overlaps(moved) == []
    # rod 1 was pushed straight along +x until the two reaches (0.65 each) cleared
    assert_allclose(offsets[1], [0.65 + 0.65 + CLEARANCE - 0.1, 0, 0])


def test_coincident_creatures_are_pushed_along_x() -> None:
    offsets, left = separate_bodies([_rod(1, 1), _rod(1, 1)])
    assert left == []
    assert_allclose(offsets[1], [1.3 + CLEARANCE, 0, 0])
