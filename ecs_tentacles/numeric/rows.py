"""Row-index helpers: a run of consecutive rows read as a slice (a copy, not a gather)."""

from __future__ import annotations

import numpy as np


def run_slice(rows: np.ndarray) -> slice | None:
    """`rows` (1-D) as one slice when they are consecutive and ascending, else None."""
    if not len(rows) or not bool(np.all(np.diff(rows) == 1)):
        return None
    return slice(int(rows[0]), int(rows[-1]) + 1)
