"""The C heap gives freed memory back during a long run (`ecs_tentacles.physics.heap`): glibc's
thresholds are fixed once a simulation is built, and the physics trims the heap every
`TRIM_FRAMES` frames. Skipped where the C library is not glibc."""

from __future__ import annotations

import ctypes
import os
from collections.abc import Callable

import pytest

from ecs_tentacles.physics import heap
from ecs_tentacles.world import World
from tests.conftest import creature_scene

glibc = pytest.mark.skipif(heap._GLIBC is None, reason="the C library is not glibc")


class MallInfo2(ctypes.Structure):
    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks keepcost".split()
        )
    ]


def libc() -> ctypes.CDLL:
    """glibc with malloc, free and mallinfo2 declared."""
    lib = ctypes.CDLL("libc.so.6")
    if not hasattr(lib, "mallinfo2"):
        pytest.skip("glibc older than 2.33 (no mallinfo2)")
    lib.malloc.restype, lib.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
    lib.free.restype, lib.free.argtypes = None, [ctypes.c_void_p]
    lib.mallinfo2.restype = MallInfo2
    return lib


@glibc
def test_a_running_simulation_trims_the_heap(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(heap, "TRIM_FRAMES", 5)
    world = make_world(creature_scene(count=3, links=4), threads=1)
    before = heap.trims
    world.step(4)
    assert heap.trims == before
    world.step(1)
    assert heap.trims == before + 1
    world.step(10)
    assert heap.trims == before + 3


@glibc
def test_freed_memory_at_the_top_of_the_heap_goes_back_once_a_world_is_built(
    make_world: Callable[..., World],
) -> None:
    """glibc raises its trim threshold by itself (to twice the size of a freed mmapped
    block: model building frees many), and kept up to that much free memory at the top
    of the heap. Once a world is built the thresholds are fixed: 10 MB of blocks freed
    at the top of the heap go back at once."""
    if {"MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_"} & set(os.environ):
        pytest.skip("the environment sets glibc's thresholds")
    make_world(creature_scene(count=3, links=4), threads=1)
    lib = libc()
    lib.free(lib.malloc(8 << 20))  # glibc would now keep up to 16 MB at the top
    blocks = [lib.malloc(100_000) for _ in range(100)]  # below the mmap threshold: heap
    for block in reversed(blocks):
        lib.free(block)
    assert lib.mallinfo2().keepcost <= heap.TRIM_THRESHOLD
