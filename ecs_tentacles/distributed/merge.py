"""Shard takes -> the take a local bake of the whole scene writes, byte for byte.

A take lists creatures in scene order, then bodies, suckers and every track's items
(goals, fur guides, ...: `ecs_tentacles.take.tracks`) creature by creature
(`ecs_tentacles.export.recording`). A shard's take does the same for its own
creatures, so merging is a stable sort of every table by the creature's index in the
whole scene, with the header's indices renumbered. The ground's meshes
(`ecs_tentacles.take.ground`) are the scene's, the same in every shard: kept once.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ecs_tentacles.take import Take
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take.header_entries import HeaderHealth, HeaderReplay, HealthEvent, ReplayClip
from ecs_tentacles.take.tracks import TakeTrack


def merge_takes(parts: Sequence[tuple[Sequence[int], Take]]) -> Take:
    """One take from (scene indices of its creatures, take) per shard."""
    first = parts[0][1]
    header: dict[str, Any] = {
        k: v for k, v in first.header.items() if k not in ("creatures", "bodies", "suckers")
    }
    for key in ("frames", "fps", "seed", "scene_sha256", take_ground.KEY):
        values = {repr(take.header.get(key)) for _, take in parts}
        if len(values) > 1:
            raise ValueError(f"shard takes differ in {key}: {sorted(values)}")
    tracks = first.track_list()
    tables: dict[str, list[tuple[int, Any]]] = {
        k: [] for k in ("creatures", "bodies", "suckers", *(t.key for t in tracks))
    }
    arrays: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    axes: dict[str, int] = {}  # array name -> its item axis
    for members, take in parts:
        h = take.header
        glob = np.asarray(members, dtype=np.int64)  # shard creature index -> scene index
        body_owner = glob[[b["creature"] for b in h["bodies"]]].reshape(-1)
        sucker_owner = body_owner[[s["body"] for s in h["suckers"]]].reshape(-1)
        body_base = len(tables["bodies"])  # placeholder ids, renumbered below
        for c, entry in enumerate(h["creatures"]):
            tables["creatures"].append((int(glob[c]), (body_base, entry)))
        for b in h["bodies"]:
            tables["bodies"].append((int(glob[b["creature"]]), b))
        for s in h["suckers"]:
            tables["suckers"].append((int(body_owner[s["body"]]), (body_base, s)))
        owners = {
            "pos": body_owner,
            "quat": body_owner,
            "sucker_attached": sucker_owner,
            "sucker_anchor": sucker_owner,
        }
        for track in tracks:
            _track_owners(track, h, glob, tables[track.key], owners, axes)
        if h.get(take_replay.KEY) is not None:  # per creature, frames first
            owners.update(dict.fromkeys(take_replay.PER_FRAME, glob))
        for name, owner in owners.items():
            value = take.array(name)
            assert value is not None
            arrays.setdefault(name, []).append((owner, np.moveaxis(value, axes.get(name, 1), 0)))
    body_map = _order([o for o, _ in tables["bodies"]])
    header["creatures"] = _creatures(tables["creatures"], body_map)
    header["bodies"] = _pick(tables["bodies"], body_map)
    header["suckers"] = [
        {**s, "body": int(body_map.new[base + s["body"]])}
        for base, s in _pick(tables["suckers"], _order([o for o, _ in tables["suckers"]]))
    ]
    for i, body in enumerate(header["bodies"]):
        body["creature"] = tables["bodies"][body_map.old[i]][0]
    for track in tracks:
        table = tables[track.key]
        order = _order([o for o, _ in table])
        if track.kind == "points":
            header[track.key] = [
                {**item, "creature": table[order.old[i]][0]}
                for i, item in enumerate(_pick(table, order))
            ]
        elif table:
            header[track.key] = {"creatures": [table[k][0] for k in order.old.tolist()]}
    header["health"] = _health(parts)
    merged = {}
    for name, pieces in arrays.items():
        owner = np.concatenate([o for o, _ in pieces])
        stacked = np.concatenate([a for _, a in pieces], axis=0)
        merged[name] = np.ascontiguousarray(
            np.moveaxis(stacked[np.argsort(owner, kind="stable")], 0, axes.get(name, 1))
        )
    # the ground is the scene's, the same in every shard (checked above): the first's
    merged.update({name: first.tracks[name] for name in take_ground.dtypes(first.header)})
    if first.header.get(take_replay.KEY) is not None:
        header[take_replay.KEY] = _replay(parts, merged)
    return Take.from_arrays(header, merged)


def _replay(
    parts: Sequence[tuple[Sequence[int], Take]], merged: dict[str, np.ndarray]
) -> HeaderReplay:
    """The merged take's replay header, its clips put into `merged`: numbered as a local
    recording numbers them (by the frame each creature first replays, then creature
    order), one per distinct clip."""
    clip_of: dict[int, tuple[np.ndarray, ReplayClip]] = {}
    for members, take in parts:
        replay = take.header[take_replay.KEY]
        for c, k in enumerate(replay["creatures"]):
            if k >= 0:
                clip_of[int(members[c])] = (
                    take.tracks[take_replay.clip_array(k)],
                    replay["clips"][k],
                )
    kind = merged["replay_kind"]
    creatures = np.full(kind.shape[1], take_replay.PHYSICAL, dtype=np.int64)
    replayed = (kind >= 0).any(axis=0)
    first = np.where(replayed, np.argmax(kind >= 0, axis=0), kind.shape[0])
    clips: list[ReplayClip] = []
    numbers: dict[bytes, int] = {}
    for c in sorted(clip_of, key=lambda c: (int(first[c]), c)):
        pose, meta = clip_of[c]
        key = pose.tobytes() + repr(sorted(meta.items())).encode()
        if key not in numbers:
            numbers[key] = len(clips)
            merged[take_replay.clip_array(len(clips))] = pose
            clips.append(meta)
        creatures[c] = numbers[key]
    return {"clips": clips, "creatures": creatures.tolist()}


def _track_owners(
    track: TakeTrack,
    header: dict[str, Any],
    glob: np.ndarray,
    table: list[tuple[int, Any]],
    owners: dict[str, np.ndarray],
    axes: dict[str, int],
) -> None:
    """Add one shard's items of `track` to its table, and its arrays' owners and axes."""
    first, second = track.arrays
    if track.kind == "points":
        items = header[track.key]
        owner = glob[[item["creature"] for item in items]].reshape(-1)
        table += [(int(glob[item["creature"]]), item) for item in items]
        owners[first] = owners[second] = owner
        axes[first] = 0
    elif header[track.key] is not None:
        owner = glob[header[track.key]["creatures"]].reshape(-1)
        owners[first] = owners[second] = owner
        table += [(int(o), None) for o in owner]


class _Order:
    """A stable sort by owner: `old[new index]` and `new[old index]`."""

    def __init__(self, owners: Sequence[int]):
        self.old = np.argsort(np.asarray(owners, dtype=np.int64), kind="stable")
        self.new = np.empty_like(self.old)
        self.new[self.old] = np.arange(len(self.old))


def _order(owners: Sequence[int]) -> _Order:
    return _Order(owners)


def _pick(table: list[tuple[int, Any]], order: _Order) -> list[Any]:
    return [dict(table[k][1]) if isinstance(table[k][1], dict) else table[k][1] for k in order.old]


def _creatures(table: list[tuple[int, Any]], body_map: _Order) -> list[dict[str, Any]]:
    out = []
    for _, (base, entry) in sorted(table, key=lambda item: item[0]):
        new = body_map.new
        out.append(
            {
                **entry,
                "mantle": int(new[base + entry["mantle"]]),
                "tentacles": [[int(new[base + b]) for b in chain] for chain in entry["tentacles"]],
            }
        )
    return out


def _health(parts: Sequence[tuple[Sequence[int], Take]]) -> HeaderHealth:
    """Every shard's physics recoveries, renumbered and in the order a local bake logs them
    (by frame, then creature)."""
    events: list[HealthEvent] = []
    for members, take in parts:
        for event in take.header.get("health", {}).get("events", []):
            events.append(
                {"frame": event["frame"], "creature": int(members[event["creature"]]),
                 "event": event["event"], "cause": event["cause"]}
            )  # fmt: skip
    events.sort(key=lambda e: (e["frame"], e["creature"]))  # stable: recovered before frozen
    return {
        "recoveries": sum(e["event"] == "recovered" for e in events),
        "frozen": sum(e["event"] == "frozen" for e in events),
        "events": events,
    }
