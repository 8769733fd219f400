"""Which thread steps which creatures: shares of rows handed out to whichever asks.

`plan` groups the active rows of all batches by batch and tier (a thread taking a
group's rows in turn keeps that model in its caches), the groups whose rows cost most
first, each row with its cost (`Batch.frame_cost`: the time its steps took lately).
Each thread of a dispatch takes shares from one `Work` until none is left: a share is
half of what is left divided among the threads (guided scheduling), so the first are
large (little bookkeeping) and the last small (no thread idles long while another
finishes). A split fixed before the step, by estimated cost, left the second of two
threads 1-1.5 ms a frame behind: a row's time depends on what the other thread does
meanwhile. Thread k always steps on scratch k of each batch, so two threads never
share a scratch MjData; which thread steps a row never changes its result
(`ecs_tentacles.physics.batch`).

Between steps the same threads may share other work whose items are independent
(`share`: a large crowd's replayed poses, `clips.replay`), in chunks taken in turn.
"""

from __future__ import annotations

import bisect
import itertools
import threading
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from ecs_tentacles.physics.batch import Batch
from ecs_tentacles.physics.tiers import FULL, KINEMATIC, REDUCED


@dataclass(frozen=True)
class Segment:
    """Some rows of one batch, stepped at one tier."""

    batch: Batch
    rows: np.ndarray
    tier: int = FULL
    cost: np.ndarray = field(default_factory=lambda: np.zeros(0))  # per row, when planned


class Work:
    """The segments of a plan handed out in shares to the `threads` threads of one
    dispatch (one thread: each segment whole)."""

    def __init__(self, segments: list[Segment], threads: int) -> None:
        self._segments = segments
        self._threads = threads
        self._lock = threading.Lock()
        # each segment's running cost totals, as lists: `bisect` on a few floats is a
        # tenth of `np.searchsorted`'s call
        self._totals = [np.cumsum(s.cost).tolist() if len(s.cost) else None for s in segments]
        self._left = float(sum(t[-1] for t in self._totals if t is not None))
        self._at = (0, 0)  # the next segment and row not taken

    def take(self) -> Segment | None:
        """The next share nobody has taken, or None when all are taken."""
        with self._lock:
            index, row = self._at
            while index < len(self._segments) and row >= len(self._segments[index].rows):
                index, row = index + 1, 0
            if index == len(self._segments):
                self._at = (index, 0)
                return None
            segment, totals = self._segments[index], self._totals[index]
            end = len(segment.rows)
            if self._threads > 1 and totals is not None:
                before = totals[row - 1] if row else 0.0
                want = before + self._left / (2 * self._threads)
                end = min(max(bisect.bisect_left(totals, want) + 1, row + 1), end)
                self._left -= totals[end - 1] - before
            self._at = (index, end)
        if row == 0 and end == len(segment.rows):
            return segment
        return Segment(segment.batch, segment.rows[row:end], segment.tier)


def plan(
    batches: list[Batch],
    active: np.ndarray,
    tier: np.ndarray,
    threads: int,
) -> list[Segment]:
    """Active rows (by creature index) of the stepped tiers: a segment per batch and tier
    with each row's cost, the segments whose rows cost most first; every tier's model
    and scratch data for `threads` threads are made first."""
    found: list[Segment] = []
    stepped = np.where(active, tier, -1)  # each creature's tier, -1 where not stepped
    levels = [stepped[batch.members] for batch in batches]
    for level in (FULL, REDUCED):
        for batch, mine in zip(batches, levels, strict=True):
            rows = np.flatnonzero(mine == level)
            if len(rows):
                batch.prepare(level, threads)
                if level == REDUCED:
                    batch.prepare(FULL, threads)  # its poses come from the full model
                found.append(Segment(batch, rows, level, batch.frame_cost(rows, level)))
    if len(found) > 1:  # dearest rows first; a stable sort keeps ties in this order
        found.sort(key=lambda segment: -float(segment.cost.mean()))
    return found


def hold_reduced(batches: list[Batch], active: np.ndarray, tier: np.ndarray, threads: int) -> None:
    """Before a frame's step: the rows about to step REDUCED hold a reduced state, the
    replayed (KINEMATIC) ones give theirs back (`Batch.hold_reduced`, `release_reduced`);
    a row asleep or frozen keeps its own."""
    for batch in batches:
        members = batch.members
        if len(batch.rstate):
            held = np.flatnonzero(batch.rslot >= 0)
            batch.release_reduced(held[tier[members[held]] == KINEMATIC])
        rows = np.flatnonzero(active[members] & (tier[members] == REDUCED))
        if len(rows):
            batch.prepare(REDUCED, threads)
            batch.hold_reduced(rows)


def step_segments(work: Work, substeps: dict[int, int], thread: int) -> None:
    """Step segments taken from `work` by their tier's `substeps` on scratch `thread`
    until none is left (runs on each thread of a dispatch)."""
    while (segment := work.take()) is not None:
        n = substeps[segment.tier]
        if n:
            segment.batch.step_rows(segment.rows, n, thread, segment.tier)


# `share`'s least items a chunk: replayed creatures' poses (`clips.kernels.place`, about
# 0.6 us each) gain from a second thread only in large crowds. 10,000 replayed, 2 threads
# (ms a frame, two runs each): quiet 5.7-5.8 -> 3.4-3.6; two busy processes beside it
# 7.2-9.2 -> 8.1-8.9. 890 (1,024 creatures) in chunks of 297 gained 0.1 ms when quiet
# (0.57-0.61 -> 0.47-0.49) and lost 0.4 beside the busy processes (0.60 -> 0.98): not shared.
SHARE_LEAST = 1000
SHARE_CHUNKS = 4  # chunks a thread at most: a thread that gets no core holds up one chunk


def share(
    pool: Executor | None,
    threads: int,
    count: int,
    work: Callable[[int, int], None],
    least: int = SHARE_LEAST,
) -> None:
    """`work(start, stop)` over items [0, count) in contiguous chunks taken in turn by
    this thread and `threads - 1` of `pool`'s, for work between steps whose items are
    independent and which releases the interpreter's lock (a numba ``nogil`` kernel):
    the same result as `work(0, count)`, whoever does which chunk.

    Chunks are taken, not dealt: on a loaded machine a pool thread that gets no core
    takes nothing (this thread does every chunk, and a helper not started by then is
    cancelled), or holds up the end by the one chunk it took. Halves dealt out made a
    1,024 crowd's replay 3.7 -> 12.2 ms a frame at load 7. Chunks of at least `least`
    items (fewer: one call on this thread)."""
    chunks = min(max(threads, 1) * SHARE_CHUNKS, count // max(least, 1))
    if pool is None or threads < 2 or chunks < 2:
        if count:
            work(0, count)
        return
    taken = itertools.count()  # (its `next` is atomic: one C call under the GIL)

    def take_chunks() -> None:
        while (k := next(taken)) < chunks:
            work(k * count // chunks, (k + 1) * count // chunks)  # `least` items or more

    helpers = [pool.submit(take_chunks) for _ in range(min(threads, chunks) - 1)]
    try:
        take_chunks()
    finally:
        for helper in helpers:
            if not helper.cancel():  # started: wait for the chunk it is on
                helper.result()
