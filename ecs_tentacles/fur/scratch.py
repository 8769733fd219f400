"""Reusable float32 work buffers for the rig (no allocation per frame)."""

from __future__ import annotations

import numpy as np

F32 = np.float32


class RigBuffers:
    """Float32 work buffers, made on first use and kept: no allocation per frame.

    One scratch serves blocks of guides one after the other (`use(n)` before each), so
    its buffers stay in cache between them; each buffer is a contiguous (*shape, n).
    """

    def __init__(self, n: int = 0) -> None:
        self.n = n
        self._memory: dict[tuple[str, tuple[int, ...]], np.ndarray] = {}
        self._views: dict[tuple[str, tuple[int, ...], int], np.ndarray] = {}

    def use(self, n: int) -> RigBuffers:
        """Hand out buffers for n guides from now on."""
        self.n = n
        return self

    def __call__(self, name: str, *shape: int) -> np.ndarray:
        """The buffer `name` of shape (*shape, n) (contents left from its last use)."""
        view = self._views.get((name, shape, self.n))
        if view is None:
            size = int(np.prod(shape, dtype=np.int64)) * self.n
            memory = self._memory.get((name, shape))
            if memory is None or len(memory) < size:
                memory = self._memory[(name, shape)] = np.empty(size, dtype=F32)
                self._views = {k: v for k, v in self._views.items() if k[:2] != (name, shape)}
            view = self._views[(name, shape, self.n)] = memory[:size].reshape(*shape, self.n)
        return view
