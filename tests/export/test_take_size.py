"""What a take of a scene holds, counted before anything is built (`export.take_size`):
the take a bake writes, frame for frame, its header entry for entry."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path
from typing import Any

from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.export.take_size import NPY_HEADERS, take_size
from ecs_tentacles.take import Take


def _mixed() -> dict[str, Any]:
    """12 creatures unlike each other: a 64-letter name, tapering links, overrides,
    suckers at the tip or on every link, goals with long radii, two furs."""
    creatures = []
    for i in range(12):
        tentacles = {
            "count": 3 + i % 3,
            "links": 3 + i,
            "end_scale": 0.37,
            "link_radius": 0.033,
            "suckers": "every_link" if i % 2 else "tip",
            "overrides": [{"index": 1, "links": 11, "end_scale": 0.61, "link_length": 0.0777}],
        }
        creature: dict[str, Any] = {
            "name": "n" * 64 if i == 3 else f"c{i}",
            "position": [4.0 * (i % 4), 4.0 * (i // 4)],
            "mantle": {"radius": 0.3 if i % 2 else 0.25, "height": 0.4},
            "tentacles": tentacles,
            "goals": [{"position": [1.0 + i, 0.0], "radius": 0.123456789}] * (i % 3),
        }
        if i in (2, 7):
            creature["fur"] = {"groom": {"count": 40 * i, "points": 3 + i}}
        creatures.append(creature)
    return {"version": 1, "name": "mixed", "creatures": creatures}


def test_what_a_bake_counts_is_what_its_take_holds(tmp_path: Path) -> None:
    """Every frame's bytes exactly; once, the header as written, give or take its
    brackets, and room for the `.npy` headers: never less than the file holds."""
    plan = BakePlan.make(_mixed(), seconds=0.1, fps=30)
    counted = take_size(plan.scene, plan.tracks)
    out = tmp_path / "mixed.npz"
    bake(plan, progress=False).save(out)
    with zipfile.ZipFile(out) as archive:  # what the reader counts against its limit
        stored = {entry.filename: entry.file_size for entry in archive.infolist()}
    header = Take.load(out).header
    assert [(p.what, p.items) for p in counted.parts] == [
        ("bodies", 458),
        ("suckers", 256),
        ("goals", 12),
        ("fur guides", 360),
        ("replay records", 12),
    ]
    assert counted.frame_bytes == 458 * 28 + 256 * 13 + 12 + 360 * 10 * 16 + 12 * 33
    arrays = sum(
        size - 128
        for name, size in stored.items()
        if name != "header.npy" and not name.startswith("replay_clip_")  # once, if any
    )
    per_frame = arrays - 12 * 12  # the goals' positions are stored once
    # guides' points are stored as 64-bit steps (12 bytes more a point than decoded)
    assert per_frame == plan.frames * (counted.frame_bytes + 360 * 10 * 12)
    entries = {key: len(json.dumps(header[key], separators=(",", ":"))) for key in header}
    bodies, suckers, goals, guides, _ = counted.parts
    # every creature is a body plan of its own: its bodies are counted, and its plan index
    plan_indices = sum(len(str(i)) + 1 for i in range(12))
    assert entries["bodies"] + entries["creatures"] + plan_indices == bodies.fixed_bytes + 2
    # the file stores each plan once, its names relative: less than counted
    packed = stored["header.npy"] - 128
    assert packed <= sum(p.fixed_bytes for p in counted.parts) + counted.base
    assert entries["suckers"] == suckers.fixed_bytes + 1
    assert entries["goals"] + 12 * 12 == goals.fixed_bytes + 1
    assert entries["guides"] == guides.fixed_bytes + len('{"creatures":[]}') - 1
    total = sum(stored.values()) - plan.frames * 360 * 10 * 12  # decoded: float32 points
    listed = len(json.dumps(header, separators=(",", ":"))) + plan_indices
    total += listed - packed  # counted as listed, plan indices too: an upper bound
    assert total <= counted.total(plan.frames) <= total + NPY_HEADERS + 1024


def _crowd(count: int, plans: int | None = None) -> dict[str, Any]:
    """`count` creatures of 8 tentacles of 60 links, a sucker on each, of `plans` body
    plans (their links' lengths differ; default: each creature its own)."""
    plans = plans or count
    creatures = [
        {"name": f"c{i}", "position": [6.0 * (i % 40), 6.0 * (i // 40)],
         "tentacles": {"count": 8, "links": 60, "suckers": "every_link",
                       "link_length": 0.05 + 1e-5 * (i % plans)}}
        for i in range(count)
    ]  # fmt: skip
    return {"version": 1, "creatures": creatures}


def test_a_header_the_reader_would_refuse_is_refused_before_anything_is_built() -> None:
    """1,000 creatures of 481 bodies and 480 suckers, each of its own body plan, name
    them in 119 MiB of header; a reader takes 64 MiB: a bake of a frame is refused. 500
    of them fit in 60 MiB; 1,000 of 10 body plans in a few (`take.compact`)."""
    assert BakePlan.make(_crowd(1000), seconds=0.05).size_problem() == (
        "the take's header would be 119 MiB for 481,000 bodies, 480,000 suckers and 1,000 replay"
        " records; a take's"
        " header holds at most 64 MiB (bake fewer creatures)"
    )
    assert BakePlan.make(_crowd(500), seconds=0.05).size_problem() is None
    assert BakePlan.make(_crowd(1000, plans=10), seconds=0.05).size_problem() is None
