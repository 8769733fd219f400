"""Zeroed tables whose memory is taken only where they are written: `untouched_zeros`.

    kp = untouched_zeros((10_000, 160))  # 12.8 MB asked, a page or so resident
    kp[stepped] = gains                  # now the pages of those rows

For per-creature tables that only some creatures use (the servo gains of the creatures
MuJoCo steps, the health check's last poses of them): in a crowd of 10,000 mostly
replayed creatures, a few hundred rows are ever written. `np.zeros` does not promise
that: below glibc's mmap threshold (32 MB once a simulation is built,
`physics.heap`) `calloc` may clear a reused heap block, which makes every page of it
resident. An anonymous mapping is zero by the kernel's promise and each page is
resident from its first write only. Reads of untouched rows read zeros (a shared zero
page).
"""

from __future__ import annotations

import mmap

import numpy as np


def untouched_zeros(shape: tuple[int, ...], dtype: type | np.dtype = np.float64) -> np.ndarray:
    """A writable C-contiguous array of zeros of `shape` whose pages are resident once
    written (an anonymous mapping, freed with the array); empty shapes are plain arrays."""
    dtype = np.dtype(dtype)
    count = int(np.prod(shape, dtype=np.int64))
    if count == 0:
        return np.zeros(shape, dtype)
    mapping = mmap.mmap(-1, count * dtype.itemsize)
    return np.frombuffer(mapping, dtype=dtype, count=count).reshape(shape)


def is_untouched(array: np.ndarray) -> bool:
    """Whether `array` is (a view of) a table `untouched_zeros` made: its memory an
    anonymous mapping (the chain of bases is followed to the buffer: a reshaped view's
    base is an array, whose base is a memoryview of the mapping)."""
    base: object = array
    while isinstance(base, np.ndarray):
        base = base.base
    if isinstance(base, memoryview):
        base = base.obj
    return isinstance(base, mmap.mmap)
