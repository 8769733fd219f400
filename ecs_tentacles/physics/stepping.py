"""Which thread steps which creatures: balanced contiguous shares of every batch's rows.

`plan` splits the active rows of all batches into at most `threads` chunks of about
equal cost (the time each row's steps took lately, `Batch.frame_cost`), each a list of
`Segment`s (a batch and some of its rows). Chunk k runs on the pool's k-th task with
scratch k of each batch, so two threads never share a scratch MjData; which thread
steps a row never changes its result (`ecs_tentacles.physics.batch`).
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


def plan(
    batches: list[Batch],
    active: np.ndarray,
    tier: np.ndarray,
    threads: int,
    also: tuple[np.ndarray, dict[int, int], float] | None = None,
) -> list[list[Segment]]:
    """Active rows (by creature index) of the stepped tiers in at most `threads` chunks of
    about equal cost; every tier's model and scratch data are made first.

    `also` = (more active creatures, their steps per tier, how many times the call's
    steps that is): stepped in the same chunks, their cost weighed by it, so one
    dispatch balances creatures that take different step counts.
    """
    pieces = []
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
                    cost = batch.frame_cost(rows, level) * weight
                    pieces.append((batch, rows, cost, level, steps))
    if not pieces:
        return []
    cost = np.cumsum(np.concatenate([c for _, _, c, _, _ in pieces]))
    cuts = np.searchsorted(cost, cost[-1] * np.arange(1, threads) / threads)
    bounds = [0, *cuts.tolist(), len(cost)]
    starts = np.cumsum([0] + [len(r) for _, r, _, _, _ in pieces])
    chunks: list[list[Segment]] = []
    for a, b in itertools.pairwise(bounds):
        if b <= a:
            continue
        chunk = []
        for (batch, rows, _, level, steps), lo, hi in zip(
            pieces, starts[:-1], starts[1:], strict=True
        ):
            s, e = max(a, lo), min(b, hi)
            if e > s:
                chunk.append(Segment(batch, rows[s - lo : e - lo], level, steps))
        chunks.append(chunk)
    return chunks


def step_segments(chunk: list[Segment], substeps: dict[int, int], thread: int) -> None:
    """Step every segment of `chunk` by its tier's `substeps` on scratch `thread` (runs on
    a pool thread)."""
    for segment in chunk:
        n = (segment.steps or substeps)[segment.tier]
        if n:
            segment.batch.step_rows(segment.rows, n, thread, segment.tier)


def bare_step(
    chunk: list[Segment],
    states: list[dict[int, np.ndarray]],
    substeps: dict[int, int],
    thread: int,
) -> None:
    """MuJoCo alone: each row's model values, set its state, step it, get it back
    (benchmarks)."""
    for segment in chunk:
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
