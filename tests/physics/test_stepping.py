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


def test_shared_work_covers_every_item_once_in_chunks_taken_by_the_threads() -> None:
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from ecs_tentacles.physics.stepping import share

    chunks: list[tuple[int, int, int]] = []
    lock = threading.Lock()
    both = threading.Barrier(2, timeout=10)  # the first two chunks: two threads, or this fails

    def work(start: int, stop: int) -> None:
        with lock:
            chunks.append((start, stop, threading.get_ident()))
            first_two = len(chunks) <= 2
        if first_two:
            both.wait()

    with ThreadPoolExecutor(2) as pool:
        share(pool, 2, 1000, work, least=100)  # 125 a chunk: 8 chunks for 2 threads
        assert sorted((a, b) for a, b, _ in chunks) == [(k, k + 125) for k in range(0, 1000, 125)]
        assert len({thread for *_, thread in chunks}) == 2

        chunks.clear()
        share(pool, 2, 199, lambda a, b: chunks.append((a, b, threading.get_ident())), least=100)
        assert chunks == [(0, 199, threading.get_ident())]  # too few for two chunks: one call
        chunks.clear()
        share(pool, 2, 0, lambda a, b: chunks.append((a, b, 0)), least=1)
        assert chunks == []

        def fails(start: int, stop: int) -> None:
            if start == 500:
                raise ValueError(f"chunk {start}")

        with pytest.raises(ValueError, match="chunk 500"):
            share(pool, 2, 1000, fails, least=1)
    share(None, 2, 1000, lambda a, b: chunks.append((a, b, 0)), least=1)  # no pool: one call
    assert chunks == [(0, 1000, 0)]


def test_shared_work_does_not_wait_for_a_thread_that_never_starts() -> None:
    """A loaded machine: the pool's thread is busy (here with another task) for longer
    than the work takes; this thread does every chunk and returns without waiting."""
    import threading
    from concurrent.futures import ThreadPoolExecutor

    from ecs_tentacles.physics.stepping import share

    release = threading.Event()
    done: list[tuple[int, int, int]] = []
    with ThreadPoolExecutor(1) as pool:
        busy = pool.submit(release.wait, 30)
        try:
            share(pool, 2, 1000, lambda a, b: done.append((a, b, threading.get_ident())), 100)
            assert not busy.done()  # returned while the pool's thread was still held
        finally:
            release.set()
    assert sorted((a, b) for a, b, _ in done) == [(k, k + 125) for k in range(0, 1000, 125)]
    assert {thread for *_, thread in done} == {threading.get_ident()}
