"""Stepping a world for many frames with a progress bar (`ecs-tentacles run`, bakes)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from tqdm import tqdm

if TYPE_CHECKING:
    from ecs_tentacles.world import World


def step_frames(
    world: World,
    frames: int,
    *,
    progress: bool = True,
    desc: str | None = None,
    on_steps: Callable[[int], None] | None = None,
) -> None:
    """Run `frames` frames of `world`, in chunks of about a tenth of a simulated second.

    With `progress`, a tqdm bar (frames, rate, ETA; labelled `desc`) goes to stderr when
    stderr is a terminal, and is cleared at the end. `on_steps(n)` is told after every
    chunk of `n` frames.
    """
    chunk = max(1, round(world.settings.fps / 10))
    with tqdm(
        total=frames,
        unit="frame",
        desc=desc,
        disable=None if progress else True,
        file=sys.stderr,
        leave=False,
    ) as bar:
        done = 0
        while done < frames:
            n = min(chunk, frames - done)
            world.step(n)
            done += n
            bar.update(n)
            if on_steps is not None:
                on_steps(n)
