"""The small scenes the spawning tests build on: creatures far enough apart not to meet."""

from __future__ import annotations


def creature_entry(
    name: str, x: float, y: float = 0.0, goal: tuple[float, float] | None = None
) -> dict:
    """A five-tentacle creature entry at (x, y), with one goal if given."""
    spec = {"name": name, "position": [x, y], "tentacles": {"count": 5, "links": 6}}
    if goal is not None:
        spec["goals"] = [{"position": list(goal)}]
    return spec


def scene_of(creatures: list[dict]) -> dict:
    """A scene of these creature entries."""
    return {"version": 1, "name": "spawning", "creatures": creatures}


APART = [
    creature_entry("a", 0.0, goal=(0.0, 3.0)),
    creature_entry("b", 6.0, goal=(6.0, -3.0)),
    creature_entry("c", 12.0, goal=(12.0, 3.0)),
]
