"""Which thread steps which creatures: rows handed out one by one to whichever asks.

`plan` lists the active rows of all batches as `Segment`s (a batch, one row, a tier),
grouped by batch and tier, the costliest groups first (`Batch.frame_cost`: the time
its steps took lately). Each thread
of a dispatch takes the next segment from a shared `Work` queue until none is left, so
no thread idles while another still has creatures (a static split by estimated cost
left the second of two threads 1-1.5 ms a frame behind: a row's measured time depends
on what the other thread does meanwhile). Thread k always steps on scratch k of each
batch, so two threads never share a scratch MjData; which thread steps a row never
changes its result (`ecs_tentacles.physics.batch`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import mujoco
import numpy as np

from ecs_tentacles.physics.batch import STATE, Batch, write_overlay
from ecs_tentacles.physics.tiers import FULL, REDUCED


@dataclass(frozen=True)
class Segment:
    """Some rows of one batch, stepped at one tier; `steps` per tier when they differ from
    the call's."""

    batch: Batch
    rows: np.ndarray
    tier: int = FULL
    steps: dict[int, int] | None = None


class Work:
    """`segments` handed out one at a time to the threads of one dispatch."""

    def __init__(self, segments: list[Segment]) -> None:
        self.segments = segments
        self._next = itertools.count()  # its next() is atomic under the GIL

    def take(self) -> Segment | None:
        """The next segment nobody has taken, or None when all are taken."""
        i = next(self._next)
        return self.segments[i] if i < len(self.segments) else None


def plan(
    batches: list[Batch],
    active: np.ndarray,
    tier: np.ndarray,
    threads: int,
    also: tuple[np.ndarray, dict[int, int], float] | None = None,
) -> list[Segment]:
    """Active rows (by creature index) of the stepped tiers, a segment each: the rows of
    one batch at one tier together (a thread taking them in turn keeps that model in its
    caches), the groups whose rows cost most first (so the last ones taken are short);
    every tier's model and scratch data for `threads` threads are made first.

    `also` = (more active creatures, their steps per tier, how many times the call's
    steps that is): stepped in the same dispatch, their cost weighed by it.
    """
    found: list[tuple[float, int, list[Segment]]] = []
    groups: list[tuple[np.ndarray, dict[int, int] | None, float]] = [(active, None, 1.0)]
    if also is not None:
        groups.append(also)
    for mask, steps, weight in groups:
        for level in (FULL, REDUCED):
            for batch in batches:
                rows = np.flatnonzero(mask[batch.members] & (tier[batch.members] == level))
                if len(rows):
                    batch.prepare(level, threads)
                    if level == REDUCED:
                        batch.prepare(FULL, threads)  # its poses come from the full model
                    cost = float(batch.frame_cost(rows, level).mean()) * weight
                    segments = [
                        Segment(batch, rows[k : k + 1], level, steps) for k in range(len(rows))
                    ]
                    found.append((-cost, len(found), segments))
    found.sort(key=lambda group: group[:2])
    return [segment for _, _, segments in found for segment in segments]


def step_segments(work: Work, substeps: dict[int, int], thread: int) -> None:
    """Step segments taken from `work` by their tier's `substeps` on scratch `thread`
    until none is left (runs on each thread of a dispatch)."""
    while (segment := work.take()) is not None:
        n = (segment.steps or substeps)[segment.tier]
        if n:
            segment.batch.step_rows(segment.rows, n, thread, segment.tier)


def bare_step(
    work: Work,
    states: list[dict[int, np.ndarray]],
    substeps: dict[int, int],
    thread: int,
) -> None:
    """MuJoCo alone: each row's model values, set its state, step it, get it back
    (benchmarks)."""
    while (segment := work.take()) is not None:
        batch = segment.batch
        scratch = batch.scratch_for(thread, segment.tier)
        m, d, rows = scratch.model, scratch.data, states[batch.index][segment.tier]
        n = substeps[segment.tier]
        for row in segment.rows.tolist():
            if segment.tier == REDUCED and batch.reduced is not None:
                batch.reduced.write_overlay(batch, m, row)
            else:
                write_overlay(batch, m, row)
            mujoco.mj_setState(m, d, rows[row], STATE)
            mujoco.mj_step(m, d, nstep=n)
            mujoco.mj_getState(m, d, rows[row], STATE)
