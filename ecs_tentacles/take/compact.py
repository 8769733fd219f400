"""A take header's bodies and suckers stored once per body plan (take format version 3).

A crowd's creatures share a few body plans, yet the header names every body and sucker
(about 150 bytes a body): 10,000 creatures of 81 bodies made a 121 MiB header. In the
file, `pack` replaces `bodies` and `suckers` with

    "body_plans": {
        "plans": [{"bodies": [{"name": "mantle", "shape": ..., "axis": ..., "radius": ...,
                               "length": ...}, ...],
                   "suckers": [{"name": "tentacles/t0/link9/sucker0", "body": 9,
                                "offset": [x, y, z]}, ...]}, ...],
        "creatures": [plan index of creature 0, of creature 1, ...]
    }

names relative to the creature (`c0007/` is implied) and a sucker's body relative to its
creature's first body. Creature c's bodies are its plan's bodies, in order, after those
of creatures 0..c-1, and so are its suckers. `unpack` gives back the header every reader
uses (`bodies` and `suckers` listed in full, creature indices set), refusing a plan
table that is unsound or would list more than `MAX_BODIES`. `pack` packs only when
unpacking gives back exactly the header it was given (a take whose bodies are not in
creature order keeps the full lists).

Standard library only: the Blender add-on runs this file as it is.
"""

from __future__ import annotations

import json
from typing import Any, TypeVar, cast

_T = TypeVar("_T")

KEY = "body_plans"
# bodies (and suckers) a plan table may list: 24,000 creatures of 81 bodies. A listed
# header is bounded by its bytes; a packed one is not, and its dicts (~0.4 KB a body)
# are built before anything else is read
MAX_BODIES = 2_000_000
_BODY_KEYS = ("axis", "length", "name", "radius", "shape")
_SUCKER_KEYS = ("body", "name", "offset")


_Part = tuple[int, str, tuple[float, ...]]  # a sucker: its body in the creature, name, offset


class PlanError(ValueError):
    """The header's `body_plans` is unsound; the message is one line naming the field."""


def pack(header: dict[str, object]) -> dict[str, object]:
    """`header` with its bodies and suckers stored per body plan, when that round-trips."""
    creatures, bodies, suckers = (header.get(k) for k in ("creatures", "bodies", "suckers"))
    if not (isinstance(creatures, list) and isinstance(bodies, list) and creatures):
        return header
    if not isinstance(suckers, list):
        return header
    try:
        table = _plans(creatures, bodies, suckers)
    except (KeyError, TypeError, ValueError, IndexError):
        return header
    packed = {k: v for k, v in header.items() if k not in ("bodies", "suckers")}
    packed[KEY] = table
    return packed


def header_text(header: dict[str, object]) -> str:
    """The header as a take file stores it: compact JSON, packed from version 3 on."""
    version = header.get("version")
    stored = pack(header) if isinstance(version, int) and version >= 3 else header
    return json.dumps(stored, sort_keys=True, separators=(",", ":"))


def unpacked(header: _T) -> _T:
    """A header as read from a file, its plan table (if any) unpacked: `unpack`, for a
    version 3 header; anything else is given back for the header's own checks."""
    if not isinstance(header, dict) or KEY not in header:
        return header
    if header.get("version") != 3:
        raise PlanError(f"header.{KEY}: only version 3 takes store bodies per plan")
    return cast(_T, unpack(header))


def unpack(header: dict[str, object]) -> dict[str, object]:
    """`header` with `bodies` and `suckers` listed in full (as it is without `body_plans`);
    raises `PlanError` when the plan table is unsound."""
    if KEY not in header:
        return header
    if "bodies" in header or "suckers" in header:
        raise PlanError(f"header.{KEY}: given with bodies or suckers listed too")
    table, creatures = header[KEY], header.get("creatures")
    if not isinstance(creatures, list) or not all(isinstance(c, dict) for c in creatures):
        raise PlanError("header.creatures: missing or not a list of objects")
    if not isinstance(table, dict) or set(table) != {"plans", "creatures"}:
        raise PlanError(f"header.{KEY}: must hold exactly plans and creatures")
    plans, of = table["plans"], table["creatures"]
    if not isinstance(plans, list) or not all(_plan_sound(p) for p in plans):
        raise PlanError(f"header.{KEY}.plans: each must hold bodies and suckers lists of objects")
    if not isinstance(of, list) or len(of) != len(creatures):
        raise PlanError(f"header.{KEY}.creatures: must give a plan for each of the creatures")
    if not all(isinstance(p, int) and not isinstance(p, bool) and 0 <= p < len(plans) for p in of):
        raise PlanError(f"header.{KEY}.creatures: must be plan indices below {len(plans)}")
    total = sum(len(plans[p]["bodies"]) for p in of)
    if total > MAX_BODIES or sum(len(plans[p]["suckers"]) for p in of) > MAX_BODIES:
        raise PlanError(f"header.{KEY}: lists more than {MAX_BODIES} bodies or suckers")
    bodies: list[dict[str, object]] = []
    suckers: list[dict[str, object]] = []
    for c, plan in enumerate(of):
        stem, first = _stem(creatures[c], c), len(bodies)
        for body in plans[plan]["bodies"]:
            bodies.append({**body, "creature": c, "name": stem + _name(body, c)})
        for sucker in plans[plan]["suckers"]:
            at = sucker.get("body")
            if not isinstance(at, int) or isinstance(at, bool) or at < 0:
                raise PlanError(f"header.{KEY}.plans[{plan}].suckers: body must be an index")
            suckers.append({**sucker, "body": first + at, "name": stem + _name(sucker, c)})
    unpacked = {k: v for k, v in header.items() if k != KEY}
    unpacked["bodies"], unpacked["suckers"] = bodies, suckers
    return unpacked


def _plans(
    creatures: list[dict[str, Any]], bodies: list[dict[str, Any]], suckers: list[dict[str, Any]]
) -> dict[str, object]:
    """The plan table of creatures whose bodies and suckers run in creature order, each
    item holding exactly the keys `unpack` gives back (else ValueError: not packed)."""
    plans: list[dict[str, list[dict[str, object]]]] = []
    index: dict[tuple[tuple[tuple[object, ...], ...], tuple[_Part, ...]], int] = {}
    of: list[int] = []
    b = s = 0
    for c, creature in enumerate(creatures):
        stem, first = creature["name"] + "/", b
        own: list[tuple[object, ...]] = []
        while b < len(bodies) and bodies[b]["creature"] == c:
            body = bodies[b]
            if len(body) != len(_BODY_KEYS) + 1 or not body["name"].startswith(stem):
                raise ValueError("a body with other keys or another creature's name")
            own.append(tuple(body[k] for k in _BODY_KEYS[:2]) + (body["name"][len(stem) :],)
                       + tuple(body[k] for k in _BODY_KEYS[3:]))  # fmt: skip
            b += 1
        parts: list[_Part] = []
        while s < len(suckers) and first <= suckers[s]["body"] < b:
            sucker = suckers[s]
            if len(sucker) != len(_SUCKER_KEYS) or not sucker["name"].startswith(stem):
                raise ValueError("a sucker with other keys or another creature's name")
            parts.append(
                (sucker["body"] - first, sucker["name"][len(stem) :], tuple(sucker["offset"]))
            )
            s += 1
        key = (tuple(own), tuple(parts))
        of.append(index.setdefault(key, len(plans)))
        if of[-1] == len(plans):
            plans.append(_plan(own, parts))
    if b != len(bodies) or s != len(suckers):
        raise ValueError("bodies or suckers out of creature order")
    return {"plans": plans, "creatures": of}


def _plan(
    bodies: list[tuple[object, ...]], suckers: list[_Part]
) -> dict[str, list[dict[str, object]]]:
    """A plan's JSON form from its creature's bodies and suckers (names relative)."""
    return {
        "bodies": [dict(zip(_BODY_KEYS, body, strict=True)) for body in bodies],
        "suckers": [dict(zip(_SUCKER_KEYS, (at, name, list(offset)), strict=True))
                    for at, name, offset in suckers],
    }  # fmt: skip


def _plan_sound(plan: object) -> bool:
    if not isinstance(plan, dict) or set(plan) != {"bodies", "suckers"}:
        return False
    return all(
        isinstance(plan[k], list) and all(isinstance(item, dict) for item in plan[k])
        for k in ("bodies", "suckers")
    )


def _stem(creature: dict[str, object], c: int) -> str:
    name = creature.get("name")
    if not isinstance(name, str):
        raise PlanError(f"header.creatures[{c}].name: missing or not a string")
    return name + "/"


def _name(item: dict[str, object], c: int) -> str:
    name = item.get("name")
    if not isinstance(name, str):
        raise PlanError(f"header.{KEY}: a name of creature {c}'s plan is not a string")
    return name
