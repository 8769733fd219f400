"""Shares of rows handed out to the stepping threads, and the step costs they are cut by."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.physics.stepping import Segment, Work, plan
from ecs_tentacles.physics.tiers import FULL, REDUCED
from ecs_tentacles.world import World
from tests.conftest import crawlers


def _shares(work: Work) -> list[Segment]:
    shares = []
    while (share := work.take()) is not None:
        shares.append(share)
    return shares


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_every_row_is_handed_out_once_in_order(
    make_world: Callable[..., World], threads: int
) -> None:
    world = make_world(crawlers(5, ahead=2.0))
    physics = world.physics
    segments = plan(physics.batches, physics.active, physics.tier, threads)
    shares = _shares(Work(segments, threads))
    handed = [(id(s.batch), int(r)) for s in shares for r in s.rows]
    planned = [(id(s.batch), int(r)) for s in segments for r in s.rows]
    assert handed == planned


def test_shares_shrink_toward_the_end_and_cover_their_cost() -> None:
    cost = np.full(16, 1.0)  # 16 rows of equal cost, 2 threads
    segment = Segment(batch=None, rows=np.arange(16), tier=FULL, cost=cost)  # type: ignore[arg-type]
    sizes = [len(share.rows) for share in _shares(Work([segment], 2))]
    assert sum(sizes) == 16
    assert sizes[0] == 4  # a quarter of what is left: half of it divided among 2 threads
    assert sizes == sorted(sizes, reverse=True) and sizes[-1] == 1


def test_stepped_rows_keep_a_running_mean_of_their_step_time(
    make_world: Callable[..., World],
) -> None:
    world = make_world(crawlers(3, ahead=2.0), threads=2)
    physics = world.physics
    batch = physics.batches[0]
    rows = np.array([int(physics.row_of[i]) for i in range(3)])
    assert (batch.step_cost[rows, FULL] == 0.0).all()  # nothing measured before a step
    world.step(1)
    first = batch.step_cost[rows, FULL].copy()
    assert (first > 0.0).all() and (first < 0.05).all()  # seconds per substep
    world.step(1)
    second = batch.step_cost[rows, FULL]
    assert (second != first).all()  # a mean moved by the new step: 0.75 old + 0.25 new
    assert (second > 0.75 * first).all()


def test_reduced_rows_keep_their_step_time_apart(make_world: Callable[..., World]) -> None:
    scene = {
        **crawlers(3, ahead=2.0),
        "physics": {"lod": {"full": 0, "reduced": 8, "hold_seconds": 0}},
    }
    world = make_world(scene, threads=2)
    world.step(3)
    physics = world.physics
    assert (physics.tier == REDUCED).all()
    batch = physics.batches[0]
    rows = np.array([int(physics.row_of[i]) for i in range(3)])
    before = batch.step_cost[rows, REDUCED].copy()
    world.step(1)
    after = batch.step_cost[rows, REDUCED]
    assert (after > 0.0).all() and (after != before).all() and (after > 0.75 * before).all()


def test_shared_work_covers_every_item_once_one_part_a_thread() -> None:
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from ecs_tentacles.physics.stepping import share

    parts: list[tuple[int, int, int]] = []
    lock = threading.Lock()
    both = threading.Barrier(3, timeout=10)  # all three parts run at once, or this fails

    def work(start: int, stop: int) -> None:
        both.wait()
        with lock:
            parts.append((start, stop, threading.get_ident()))

    with ThreadPoolExecutor(3) as pool:
        share(pool, 3, 1000, work, least=100)
        assert sorted((a, b) for a, b, _ in parts) == [(0, 333), (333, 666), (666, 1000)]
        assert len({thread for *_, thread in parts}) == 3
        assert threading.get_ident() in {thread for *_, thread in parts}  # the caller took one

        parts.clear()
        share(pool, 3, 199, lambda a, b: parts.append((a, b, threading.get_ident())), least=100)
        assert parts == [(0, 199, threading.get_ident())]  # too few for two parts: one call here
        parts.clear()
        share(pool, 3, 0, lambda a, b: parts.append((a, b, 0)), least=1)
        assert parts == []

        def fails(start: int, stop: int) -> None:
            if start:
                raise ValueError(f"part {start}")

        with pytest.raises(ValueError, match="part 500"):
            share(pool, 2, 1000, fails, least=1)
    share(None, 2, 1000, lambda a, b: parts.append((a, b, 0)), least=1)  # no pool: one call
    assert parts == [(0, 1000, 0)]
