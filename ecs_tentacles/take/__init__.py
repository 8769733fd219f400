"""Takes: every frame of a simulation in one compact, reproducible npz file.

    take = Take.load("octopus.npz")      # Take.save(path) writes one atomically

Modules: `format` (the `Take` and the file's layout), `read` (reading and checking a
file that may lie), `tracks` (the tracks plugins declare: `TakeTrack`), `ground` (the
terrain's meshes in a take), `roster` (creatures that came or went).
"""

from __future__ import annotations

from ecs_tentacles.take.format import (
    ARRAYS,
    FORMAT,
    VERSION,
    Take,
    TakeError,
    TakeTrack,
    write_npz,
)

__all__ = ["ARRAYS", "FORMAT", "VERSION", "Take", "TakeError", "TakeTrack", "write_npz"]
