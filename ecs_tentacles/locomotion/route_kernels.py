"""The numba kernel of route planning (`locomotion.navigation.CostGrid.route`): the
minimum-cost path across a cost grid and its pulling tight, in one call.

Optional, as the other kernels are (`ecs_tentacles.numeric.optional_kernels`): `route`
uses it only when numba is installed (`ECS_TENTACLES_ROUTES=numpy` turns it off) and
otherwise asks scikit-image's `MCP_Geometric` and pulls the path tight in Python. Both
give the same cells bit for bit: this is the same Dijkstra search as scikit-image's
(the eight neighbours in its order, its travel cost
`length * 0.5 * (cost + next cost)`, a cell's predecessor replaced only by a strictly
lower cost, the search stopped when the end cell is taken) on the same heap (its
tournament tree of `levels` levels over the values in push order, a pop taking the
last level's pair by `<=`, a removal moving the last value into the hole, a level added
when full and dropped when under a quarter full), so equal costs are taken in the same
order and give the same path; the tightening samples each line at the points numpy's
`linspace` and `round` give. tests/locomotion/test_navigation.py compares the two on
rocky and walled grids. A 256-creature crowd on the rocky preset plans its first
frame's routes in 2.8-3.0 s of CPU here against 8.1-8.3 s through scikit-image and
Python (whose pulling tight's line checks, quadratic in a path's length, took a third
of it); what is left is the search itself, which takes some 60 % of the grid's cells
before it reaches a goal across the crowd.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_MIN_LEVELS = 7  # scikit-image's heap: an initial capacity of 128 values


@njit(cache=True, nogil=True)
def _update_one(values: np.ndarray, levels: int, i: int) -> None:
    """The tree's minima above value `i` (absolute index) brought up to date: each
    parent the smaller of its pair (the right one when they tie), as scikit-image's
    heap sets them, stopping where a parent keeps its value (the ones above it are
    then up to date too: each is set from its own pair only)."""
    if i % 2 == 0:
        i -= 1
    for _ in range(levels, 1, -1):
        parent = (i - 1) // 2
        smaller = values[i] if values[i] < values[i + 1] else values[i + 1]
        if smaller == values[parent]:
            return
        values[parent] = smaller
        i = parent if parent % 2 else parent - 1


@njit(cache=True, nogil=True)
def _relevel(values: np.ndarray, levels: int, count: int, change: int) -> int:
    """The heap's tree given `change` (+1 or -1) levels in place: the `count` values
    moved in order to the new last level, inf around them and every minimum above them
    made anew, as scikit-image's heap does in new arrays. The new number of levels."""
    new_levels = levels + change
    start, old_start = (1 << new_levels) - 1, (1 << levels) - 1
    for i in range(count):  # the two last levels do not overlap
        values[start + i] = values[old_start + i]
    values[:start] = np.inf
    values[start + count : 2 << new_levels] = np.inf
    for level in range(new_levels, 1, -1):
        first = (1 << level) - 1
        for i in range(first, first + (1 << level), 2):
            parent = (i - 1) // 2
            if values[i] < values[i + 1]:
                values[parent] = values[i]
            else:
                values[parent] = values[i + 1]
    return new_levels


@njit(cache=True, nogil=True)
def _search(costs: np.ndarray, begin: int, end: int) -> np.ndarray:
    """Each cell's step from its predecessor (m: rows m // 3 - 1 and columns m % 3 - 1;
    -1 the start, -2 not reached) on the minimum-cost paths from cell `begin`
    (flat indices of `costs` (rows, columns)), searched until `end` is taken; `end`'s
    entry is -2 when no path reaches it. (The heap holds cells by name only, so their
    numbering, row-major here, does not change the order they are taken in.)"""
    rows, columns = costs.shape
    size = rows * columns
    diagonal = math.sqrt(2.0)
    taken = np.zeros(size, dtype=np.bool_)
    steps = np.empty(size, dtype=np.int8)
    crossref = np.empty(size, dtype=np.int64)  # cell -> its place in the heap
    for cell in range(size):
        steps[cell] = -2
        crossref[cell] = -1
    levels = _MIN_LEVELS
    most = levels  # the levels the heap can grow to: room for every cell
    while (1 << most) <= size:
        most += 1
    values = np.empty(2 << most)  # the tree of `levels` levels: its first 2 << levels
    for i in range(2 << levels):
        values[i] = np.inf
    references = np.empty(1 << most, dtype=np.int64)  # the cells, in the order of the values
    # the start, at cost 0
    steps[begin] = -1
    values[(1 << levels) - 1] = 0.0
    references[0] = begin
    crossref[begin] = 0
    count = 1
    _update_one(values, levels, (1 << levels) - 1)
    for _ in range(size):
        if count == 0:
            break
        # pop: down the tree by <=, then the last level's pair
        i = 1
        for _level in range(1, levels):  # the left child when <=, else the right
            i = i * 2 + 1 + 2 * (not values[i] <= values[i + 1])
        i += not values[i] <= values[i + 1]
        first = (1 << levels) - 1
        cumulative = values[i]
        index = references[i - first]
        # remove it: the last value moves into its place
        last = first + count - 1
        hole, tail = i - first, count - 1
        crossref[references[tail]] = hole
        crossref[references[hole]] = -1
        values[i] = values[last]
        references[hole] = references[tail]
        values[last] = np.inf
        count -= 1
        if levels > _MIN_LEVELS and count < (1 << (levels - 2)):
            levels = _relevel(values, levels, count, -1)
        else:
            _update_one(values, levels, i)
            _update_one(values, levels, last)
        taken[index] = True
        if index == end:
            break
        row, column = index // columns, index % columns
        cost = costs[row, column]
        for m in range(9):  # the eight neighbours in scikit-image's order: by row, column
            if m == 4:
                continue
            r, c = row + m // 3 - 1, column + m % 3 - 1
            if r < 0 or r >= rows or c < 0 or c >= columns:
                continue
            neighbour = r * columns + c
            if taken[neighbour]:
                continue
            next_cost = costs[r, c]
            if next_cost < 0 or next_cost == np.inf:
                continue
            length = 1.0 if m % 2 else diagonal  # along a row or column, or diagonal
            total = cumulative + length * 0.5 * (cost + next_cost)
            if total == np.inf:
                continue
            place = crossref[neighbour]
            if place != -1:  # queued: lowered only by a strictly lower cost
                at = (1 << levels) - 1 + place
                if values[at] > total:
                    values[at] = total
                    _update_one(values, levels, at)
                    steps[neighbour] = m
                continue
            if count >= (1 << levels):
                levels = _relevel(values, levels, count, 1)
            at = (1 << levels) - 1 + count
            values[at] = total
            references[count] = neighbour
            crossref[neighbour] = count
            count += 1
            _update_one(values, levels, at)
            steps[neighbour] = m
    if not taken[end]:
        steps[end] = -2
    return steps


@njit(cache=True, nogil=True)
def _clear(costs: np.ndarray, r0: int, c0: int, r1: int, c1: int) -> bool:
    """Whether the line from cell (r0, c0) to (r1, c1) crosses only finite costs, sampled
    at twice its longer side's cells as `CostGrid._clear` samples it."""
    dr, dc = r1 - r0, c1 - c0
    samples = max(abs(dr), abs(dc), 1) * 2
    step = 1.0 / samples
    for k in range(samples + 1):
        t = k * step if k < samples else 1.0
        r = int(np.rint(r0 + t * dr))
        c = int(np.rint(c0 + t * dc))
        if not np.isfinite(costs[r, c]):
            return False
    return True


@njit(cache=True, nogil=True)
def route_cells(costs: np.ndarray, begin: np.ndarray, end: np.ndarray) -> np.ndarray:
    """The cells (k, 2: row, column) of the minimum-cost path from cell `begin` to cell
    `end` (row, column) on `costs` (inf: impassable), pulled tight: from each kept cell
    the farthest later one of the path in plain sight is kept next. (0, 2) when no path
    joins them."""
    columns = costs.shape[1]
    steps = _search(costs, begin[0] * columns + begin[1], end[0] * columns + end[1])
    n, r, c = 1, end[0], end[1]
    if steps[r * columns + c] == -2:
        return np.empty((0, 2), dtype=np.int64)
    while steps[r * columns + c] != -1:  # back from the end to the start
        m = steps[r * columns + c]
        r, c = r - (m // 3 - 1), c - (m % 3 - 1)
        n += 1
    cells = np.empty((n, 2), dtype=np.int64)
    r, c = end[0], end[1]
    for i in range(n - 1, -1, -1):
        cells[i, 0], cells[i, 1] = r, c
        m = steps[r * columns + c]
        r, c = r - (m // 3 - 1), c - (m % 3 - 1)
    kept = np.empty((n, 2), dtype=np.int64)
    kept[0, 0], kept[0, 1] = cells[0, 0], cells[0, 1]
    count, i = 1, 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not _clear(costs, cells[i, 0], cells[i, 1], cells[j, 0], cells[j, 1]):
            j -= 1
        kept[count, 0], kept[count, 1] = cells[j, 0], cells[j, 1]
        count += 1
        i = j
    return kept[:count]
