"""Vector helpers for whole arrays of vectors."""

from __future__ import annotations

import numpy as np


def unit_rows(vectors: np.ndarray) -> np.ndarray:
    """The vectors along the last axis scaled to length 1; those shorter than 1e-12 are
    zero (a creature with nothing to steer by steers nowhere)."""
    length = np.linalg.norm(vectors, axis=-1, keepdims=True)
    unit: np.ndarray = np.divide(vectors, length, out=np.zeros_like(vectors), where=length > 1e-12)
    return unit
