"""The roster in a take: which creatures are there at each frame.

A take recorded while no creature was spawned or despawned has no `header["roster"]`
(or null) and every creature is there at every frame: nothing changes for it. When the
roster changed during the recording, `header["roster"]` is `{"changes": n}` (how many
spawns and despawns) and one more array follows every other:

    creature_visible  bool  (frames, creatures)   the creature exists at that frame

A creature spawned during the recording is listed like any other (its bodies and
suckers after everyone's before it); before it came, its bodies hold the pose it came
in. A despawned creature's bodies hold their last pose. Exporters hide a creature
while it is not there (visibility keys in USD, a zero scale in glTF).
"""

from __future__ import annotations

from typing import Any

import numpy as np

KEY = "roster"
ARRAY = "creature_visible"
MAX_CHANGES = 1_000_000


def problem(header: dict[str, object]) -> str | None:
    """The first problem of `header["roster"]`, or None."""
    roster = header.get(KEY)
    if roster is None:
        return None
    if not isinstance(roster, dict) or set(roster) != {"changes"}:
        return f"header.{KEY}: must be null or an object with changes"
    changes = roster["changes"]
    if isinstance(changes, bool) or not isinstance(changes, int):
        return f"header.{KEY}.changes: must be a whole number"
    if not 1 <= changes <= MAX_CHANGES:
        return f"header.{KEY}.changes: must be in [1, {MAX_CHANGES}], got {changes}"
    return None


def shapes(header: dict[str, Any]) -> dict[str, tuple[int, ...]]:
    """Array name -> shape for a sound header (none when the roster never changed)."""
    if header.get(KEY) is None:
        return {}
    return {ARRAY: (header["frames"], len(header["creatures"]))}


def dtypes(header: dict[str, object]) -> dict[str, np.dtype[np.generic]]:
    """Array name -> dtype, in file order, for a sound header."""
    return {} if header.get(KEY) is None else {ARRAY: np.dtype(np.bool_)}


def visible(header: dict[str, Any], arrays: dict[str, np.ndarray]) -> np.ndarray:
    """(frames, creatures) bool: which creatures are there at each frame."""
    if header.get(KEY) is None:
        return np.ones((header["frames"], len(header["creatures"])), dtype=bool)
    return np.asarray(arrays[ARRAY], dtype=bool)


def spans(shown: np.ndarray) -> list[tuple[int, bool]]:
    """Where one creature's visibility changes: (frame, visible from then), starting
    with frame 0 (for visibility keys)."""
    shown = np.asarray(shown, dtype=bool)
    if not len(shown):
        return []
    changes = np.flatnonzero(np.diff(shown.astype(np.int8))) + 1
    return [(0, bool(shown[0]))] + [(int(f), bool(shown[f])) for f in changes]
