"""A frame with creatures near another: their rounds in order, the rest stepped around them.

Creatures near another take a frame's steps in rounds, their contact proxies moved
between rounds (`PhysicsBackend.step`); every other creature (the rest) takes all its
steps at once. Stepping the rounds one after the other on every thread left the
threads idle whenever a round had fewer rows than threads: 16 crossing octopuses with
one of them near another stepped that one's last three rounds on one thread of two,
about 1 ms of a 11 ms frame. Here each thread takes a share of the current round when
one is left, else a share of the rest, so the rest fills those gaps.

Results do not change: a row's step reads only its own row, and the only thing that
runs between rounds, the proxies' refresh, calls `ready(creatures)` before it reads a
creature's last step or writes its proxies. When one of them is of the rest,
`ready` first steps all of the rest to the end of the frame, as stepping the rounds
one after the other did before the first refresh.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable

import numpy as np

from ecs_tentacles.physics.stepping import Segment, Work
from ecs_tentacles.physics.tiers import FULL, REDUCED

Steps = dict[int, int]  # steps per tier
Ready = Callable[[np.ndarray], None]  # (creatures,): step them to the frame's end first


class Rounds:
    """The shares of one frame: the current round's first, then the rest's, handed to
    whichever thread asks (`helper` on the pool's threads; the calling thread runs the
    rounds with `round` and finishes with `settle`)."""

    def __init__(self, rest: list[Segment], rest_steps: Steps, threads: int) -> None:
        self._rest = Work(rest, threads)
        self._rest_steps = rest_steps
        self._threads = threads
        self._round: tuple[Work, Steps] | None = None
        self._changed = threading.Condition()
        self._stepping = [0, 0]  # shares being stepped: of the round, of the rest
        self._closed = False
        self.settled = not rest

    def helper(self, thread: int) -> None:
        """Step shares on scratch `thread` until the frame is closed and nothing is left."""
        while (taken := self._next(of_round=True, of_rest=True, wait=True)) is not None:
            self._step(*taken, thread)

    def round(self, segments: list[Segment], steps: Steps) -> None:
        """Step one round of `segments` by `steps` on every thread that has no share of
        the rest in hand; returns when all of it is stepped (this thread steps too)."""
        work = Work(segments, self._threads)
        with self._changed:  # this thread takes the first share before a helper can
            first = work.take()
            self._stepping[0] += first is not None
            self._round = (work, steps)
            self._changed.notify_all()
        taken = None if first is None else (first, steps, 0)
        while taken is not None:
            self._step(*taken, 0)
            taken = self._next(of_round=True, of_rest=False, wait=False)
        self._wait_until_stepped(0)
        self._round = None

    def settle(self) -> None:
        """Step all of the rest (this thread steps too); returns when it is stepped."""
        if self.settled:
            return
        while (taken := self._next(of_round=False, of_rest=True, wait=False)) is not None:
            self._step(*taken, 0)
        self._wait_until_stepped(1)
        self.settled = True

    def close(self) -> None:
        """No round comes any more: helpers leave once the rest is all taken."""
        with self._changed:
            self._closed = True
            self._changed.notify_all()

    def _next(
        self, *, of_round: bool, of_rest: bool, wait: bool
    ) -> tuple[Segment, Steps, int] | None:
        """A share of the current round (`of_round`), else of the rest (`of_rest`),
        counted as being stepped; None when there is none (with `wait`: after waiting for
        another round until the frame is closed)."""
        with self._changed:
            while True:
                if of_round and self._round is not None:
                    work, steps = self._round
                    if (segment := work.take()) is not None:
                        self._stepping[0] += 1
                        return segment, steps, 0
                if of_rest and (segment := self._rest.take()) is not None:
                    self._stepping[1] += 1
                    return segment, self._rest_steps, 1
                if not wait or self._closed:
                    return None
                self._changed.wait()

    def _wait_until_stepped(self, kind: int) -> None:
        """Until no share of `kind` (0 the round, 1 the rest) is being stepped."""
        with self._changed:
            while self._stepping[kind]:
                self._changed.wait()

    def _step(self, segment: Segment, steps: Steps, kind: int, thread: int) -> None:
        try:
            n = steps[segment.tier]
            if n:
                segment.batch.step_rows(segment.rows, n, thread, segment.tier)
        finally:
            with self._changed:
                self._stepping[kind] -= 1
                self._changed.notify_all()


def round_steps(
    substeps: int, reduced: int, rounds: int, stepping: list[int] | None = None
) -> list[Steps]:
    """A frame's steps in `rounds` rounds, each round's steps per tier (FULL ones of
    `substeps`, REDUCED ones of `reduced`, spread as evenly as whole numbers allow).
    Rounds in which no tier steps are left out (at 3 substeps the FULL tier's split
    1, 1, 0, 1 leaves the REDUCED step alone in the third); with `stepping`, the tiers of
    the creatures stepped in rounds, so are those in which none of these steps, with the
    proxies' catch-up before them (`PhysicsBackend.step`)."""
    parts = [
        {FULL: n, REDUCED: r}
        for n, r in zip(_split(substeps, rounds), _split(reduced, rounds), strict=True)
        if n or r
    ]
    if stepping is not None:
        parts = [part for part in parts if any(part.get(t, 0) for t in stepping)]
    return parts


@functools.cache
def _split(steps: int, rounds: int) -> tuple[int, ...]:
    """`steps` in `rounds` parts as equal as whole numbers allow (a world asks the same
    few every frame: worked out once)."""
    return tuple(int(n) for n in np.diff(np.linspace(0, steps, rounds + 1).round()))
