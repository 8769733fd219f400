"""Progress on stderr: stepping a world for many frames with a bar (`run`, bakes), a bar
for any other counted work (`bar`: writing a file body by body or byte by byte), and a
status line for work that has no count (`status`: loading, building, validating).

Every one is drawn only when asked (`progress`: the commands' `--quiet` turns it off)
and stderr is a terminal, on stderr, and cleared when the work ends."""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, NoReturn

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
    until: Callable[[], bool] | None = None,
) -> int:
    """Run `frames` frames of `world`, in chunks of about a tenth of a simulated second;
    the frames run.

    With `progress`, a tqdm bar (frames, rate, ETA; labelled `desc`) goes to stderr when
    stderr is a terminal, and is cleared at the end. `on_steps(n)` is told after every
    chunk of `n` frames. With `until`, it is asked after every frame and the run stops
    early once it says True (a game won or lost).
    """
    chunk = 1 if until is not None else max(1, round(world.settings.fps / 10))
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
            if until is not None and until():
                break
    return done


def bar(total: int, desc: str, unit: str, *, progress: bool = True) -> tqdm[NoReturn]:
    """A tqdm bar for `total` `unit`s of work labelled `desc` (bytes are shown scaled:
    kB, MB, GB); `bar.update(n)` as n are done. Use it as a context manager."""
    scaled = unit == "B"
    return tqdm(
        total=total,
        desc=desc,
        unit=unit,
        unit_scale=scaled,
        unit_divisor=1024 if scaled else 1000,
        disable=None if progress else True,
        file=sys.stderr,
        leave=False,
    )


@contextlib.contextmanager
def status(text: str, *, progress: bool = True) -> Iterator[None]:
    """`text ...` on stderr while the block runs, when `progress` and stderr is a terminal;
    the line is cleared at the end, or kept with the seconds it took when that was long
    (`LONG_SECONDS`), so a slow step says where the time went."""
    stream = sys.stderr
    shown = progress and stream.isatty()
    if shown:
        stream.write(f"{text} ...")
        stream.flush()
    start = time.perf_counter()
    try:
        yield
    finally:
        if shown:
            took = time.perf_counter() - start
            end = f" {took:.1f} s\n" if took >= LONG_SECONDS else "\r\x1b[K"
            stream.write(end)
            stream.flush()


LONG_SECONDS = 2.0
