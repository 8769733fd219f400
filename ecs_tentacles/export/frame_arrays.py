"""A recording's per-frame arrays (frames first, then items): made room for, widened when
items join, a frame gathered from a store's rows (`export.recording.TakeRecorder`)."""

from __future__ import annotations

import numpy as np


def resized_frames(old: np.ndarray, frames: int) -> np.ndarray:
    """`old` with room for `frames` frames (its first frame kept)."""
    grown = np.empty((max(frames, 1), *old.shape[1:]), old.dtype)
    grown[:1] = old[:1]
    return grown


def doubled(old: np.ndarray) -> np.ndarray:
    """`old` with room for twice its frames (the first ones copied)."""
    grown = np.empty((2 * len(old), *old.shape[1:]), old.dtype)
    grown[: len(old)] = old
    return grown


def widen(frames: np.ndarray, now: np.ndarray) -> np.ndarray:
    """`frames` (capacity, items, ...) with items appended, every frame holding `now`."""
    extra = np.broadcast_to(np.asarray(now, dtype=frames.dtype), (len(frames), *now.shape))
    return np.concatenate([frames, extra], axis=1)


def gather(
    frames: np.ndarray,
    i: int,
    values: np.ndarray,
    rows: np.ndarray,
    before: np.ndarray | None = None,
    fill: object = None,
) -> None:
    """Frame `i` of `frames` from `values[rows]`; items whose row is gone (-1) hold
    `before` (the previous frame's values; None: 0) or `fill`."""
    live = rows >= 0
    frames[i, live] = values[rows[live]]
    if not live.all():
        if fill is not None:
            frames[i, ~live] = fill
        elif before is not None:
            frames[i, ~live] = before[~live]
        else:
            frames[i, ~live] = 0
