"""Keyframed tracks and easing, evaluated for every channel at once.

A track is a list of keys ``{"time", "value", "easing"}``; the easing of a key shapes
the segment that leaves it:

- ``linear``: constant speed;
- ``ease``: slow-out of this key and slow-in to the next (smoothstep, 3u^2 - 2u^3);
- ``slow_out``: leaves this key slowly and arrives at full speed (u^2);
- ``slow_in``: leaves at full speed and settles slowly into the next key (1 - (1 - u)^2);
- ``step``: holds this key's value until the next key.

Before the first key a track holds the first value, after the last the last value.
A vector track (a position) is three scalar channels. `TrackSet` packs any number of
scalar channels into flat arrays and evaluates them all with one `searchsorted`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

EASINGS = ("linear", "ease", "slow_out", "slow_in", "step")
EASING_CODE = {name: code for code, name in enumerate(EASINGS)}


def ease(u: np.ndarray, code: np.ndarray) -> np.ndarray:
    """Eased fraction of each segment: `u` in [0, 1], `code` indexes EASINGS."""
    u = np.clip(u, 0.0, 1.0)
    return np.select(
        [code == 0, code == 1, code == 2, code == 3],
        [u, u * u * (3.0 - 2.0 * u), u * u, 1.0 - (1.0 - u) ** 2],
        default=np.where(u >= 1.0, 1.0, 0.0),
    )


@dataclass(frozen=True)
class Channel:
    """One scalar channel: keys (times increasing), values and easing codes; where it goes."""

    row: int  # target row (a control or threat)
    column: int  # target column (meaning set by the owner of the TrackSet)
    times: np.ndarray
    values: np.ndarray
    easings: np.ndarray


def channels_from_keys(
    row: int, columns: Sequence[int], keys: Sequence[dict[str, object]], value_key: str = "value"
) -> list[Channel]:
    """Scalar channels of a scene track; a vector value gives one channel per column."""
    times = np.array([float(k["time"]) for k in keys])  # type: ignore[arg-type]
    values = np.array([k[value_key] for k in keys], dtype=np.float64).reshape(len(keys), -1)
    easings = np.array([EASING_CODE[str(k.get("easing", "ease"))] for k in keys])
    return [
        Channel(row, column, times, values[:, i].copy(), easings)
        for i, column in enumerate(columns)
    ]


class TrackSet:
    """Scalar channels packed for vectorised evaluation."""

    def __init__(self, channels: Sequence[Channel]):
        self.rows = np.array([c.row for c in channels], dtype=np.int64)
        self.columns = np.array([c.column for c in channels], dtype=np.int64)
        counts = np.array([len(c.times) for c in channels], dtype=np.int64)
        self.first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
        self.last = self.first + counts - 1
        empty = np.zeros(0)
        self.times = np.concatenate([c.times for c in channels]) if channels else empty
        self.values = np.concatenate([c.values for c in channels]) if channels else empty
        self.easings = (
            np.concatenate([c.easings for c in channels]) if channels else np.zeros(0, np.int64)
        )
        # channel k's times shifted by k * span make one increasing array to search
        span = float(self.times.max() - self.times.min() + 1.0) if channels else 1.0
        self._low = float(self.times.min()) if channels else 0.0
        self._offset = np.arange(len(channels)) * span
        channel_of_key = np.repeat(np.arange(len(channels)), counts)
        self._shifted = self.times + self._offset[channel_of_key] if channels else empty
        self._span = span

    def __len__(self) -> int:
        return len(self.rows)

    def evaluate(self, t: float) -> np.ndarray:
        """Every channel's value at time `t`."""
        if not len(self):
            return np.zeros(0)
        local = min(max(t, self._low), self._low + self._span - 1.0)
        key = np.searchsorted(self._shifted, local + self._offset, side="right") - 1
        key = np.clip(key, self.first, self.last)
        nxt = np.minimum(key + 1, self.last)
        t0, t1 = self.times[key], self.times[nxt]
        gap = np.where(nxt > key, t1 - t0, 1.0)
        with np.errstate(over="ignore"):  # keys a few ulps apart: +-inf, which `ease` clips
            u = np.where(nxt > key, (t - t0) / gap, 0.0)
        v0 = self.values[key]
        result: np.ndarray = v0 + (self.values[nxt] - v0) * ease(u, self.easings[key])
        return result
