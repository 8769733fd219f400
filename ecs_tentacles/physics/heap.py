"""Give the C heap's free pages back to the system: `trim()` (glibc's `malloc_trim`).

A frame allocates and frees megabytes of numpy temporaries whose sizes change with the
scene (the contact proxies' candidate bodies, the health check's moved bodies: 17.7 MB
a frame for 64 creatures on rocky ground, 4.4 MB of it in blocks of 64-320 KB). glibc
serves such blocks from its heap, not from mmap, once it has raised its mmap threshold
(it does so after freeing a large mmapped block, and building models frees many), and
what is freed stays in the process: at the top of the heap up to twice that threshold,
in holes below live blocks without limit. Nothing live grows, yet the resident size
does: 288 -> 319 MB in ten minutes for that crowd, and a trim every two seconds alone
still left the heap's top holding up to 11 MB of free memory between trims (the
threshold had climbed past 5 MB).

So two things, both once a simulation is built (`PhysicsBackend`):
- `settle()` fixes glibc's thresholds (`mallopt`), which also stops their climbing:
  blocks from `MMAP_THRESHOLD` (32 MB, glibc's ceiling) up are mmapped, and the top of
  the heap is given back by `free` itself past `TRIM_THRESHOLD` (1 MB): the trim
  threshold is what bounds the heap's top. A user's own
  `MALLOC_MMAP_THRESHOLD_` / `MALLOC_TRIM_THRESHOLD_` are left as they are.
- `trim()` (`malloc_trim(0)`) returns every whole free page in holes below live blocks,
  in every arena; the physics calls it every `TRIM_FRAMES` frames (`PhysicsBackend.step`),
  0.1-5 ms each time on that crowd's 90 MB heap.

Elsewhere than glibc (macOS, musl) both do nothing and say so (False).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys
from collections.abc import Callable

import numpy as np

TRIM_FRAMES = 120  # frames between two trims of a running simulation
# bytes: blocks this big or bigger are mmapped. glibc's own ceiling: a lower one (256 KB
# was tried) makes every large per-frame temporary a fresh mapping whose pages fault in
# each frame (10,000 creatures: 178 and 187 against 145 and 170 ms a frame)
MMAP_THRESHOLD = 32 * 1024 * 1024
TRIM_THRESHOLD = 1024 * 1024  # bytes: free memory at the heap's top beyond this goes back
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt's parameter numbers (malloc.h)


def _glibc() -> tuple[Callable[[int], int], Callable[[int, int], int]] | None:
    """glibc's `malloc_trim` and `mallopt`, or None where there are none."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim, mallopt = libc.malloc_trim, libc.mallopt
    except (OSError, AttributeError):  # not glibc (musl has no malloc_trim)
        return None
    trim.argtypes, trim.restype = [ctypes.c_size_t], ctypes.c_int
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return trim, mallopt


_GLIBC = _glibc()
trims = 0  # how many times `trim` gave memory back (tests read it)
settled = False  # `settle` set the thresholds


def settle() -> bool:
    """Fix glibc's mmap and trim thresholds (once; see the module doc); False where that
    cannot be done or the environment already sets them."""
    global settled
    if _GLIBC is None:
        return False
    if settled:
        return True
    if {"MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_"} & set(os.environ):
        return False
    mallopt = _GLIBC[1]
    settled = bool(
        mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD) and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD)
    )
    return settled


def trim() -> bool:
    """Return the heap's free pages to the system; False where that cannot be done."""
    global trims
    if _GLIBC is None:
        return False
    _GLIBC[0](0)
    trims += 1
    return True


def resident_bytes(array: np.ndarray) -> int | None:
    """How much of the memory under `array` (its base's whole buffer) is resident now,
    in bytes of whole pages (`mincore`); None off Linux. For measuring (tools, tests):
    numpy asks for transparent huge pages for arrays of 4 MB or more, so one write can
    make 2 MB of such an array resident."""
    if not sys.platform.startswith("linux"):
        return None
    while isinstance(array.base, np.ndarray):
        array = array.base
    if not array.nbytes:
        return 0
    page = os.sysconf("SC_PAGE_SIZE")
    start = array.ctypes.data // page * page
    length = array.ctypes.data + array.nbytes - start
    pages = -(-length // page)
    vector = bytearray(pages)
    mincore = ctypes.CDLL(None, use_errno=True).mincore
    mincore.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
    buffer = (ctypes.c_ubyte * pages).from_buffer(vector)
    if mincore(ctypes.c_void_p(start), ctypes.c_size_t(length), buffer) != 0:
        raise OSError(ctypes.get_errno(), "mincore failed")
    return int((np.frombuffer(vector, dtype=np.uint8) & 1).sum()) * page
