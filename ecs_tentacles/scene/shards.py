"""The scene's optional `shards` field: every creature, by name, in exactly one shard.

    "shards": [["octo_a", "octo_b"], ["octo_c"]]

A distributed bake (`ecs_tentacles.distributed`) bakes each shard as one task; these
are the rules the schema cannot express, checked with the scene's other semantic rules.
"""

from __future__ import annotations

import json
from collections.abc import Mapping

from ecs_tentacles.scene.spec import creature_specs

JsonPath = tuple[str | int, ...]


def shard_problems(scene: Mapping[str, object]) -> list[tuple[JsonPath, str]]:
    """(JSON path, message) for each unknown, repeated or missing creature of `shards`
    (a schema-valid scene's: lists of names)."""
    shards = scene.get("shards")
    if not isinstance(shards, list):
        return []
    names = [creature["name"] for creature in creature_specs(scene)]
    known = set(names)
    seen: dict[str, tuple[int, int]] = {}
    problems: list[tuple[JsonPath, str]] = []
    for i, shard in enumerate(shards):
        for j, name in enumerate(shard):
            where: JsonPath = ("shards", i, j)
            if name not in known:
                problems.append((where, f"no creature named {json.dumps(name)}"))
            elif name in seen:
                first = "shards[{}][{}]".format(*seen[name])
                problems.append((where, f"{json.dumps(name)} is already in {first}"))
            else:
                seen[name] = (i, j)
    missing = [name for name in names if name not in seen]
    if missing:
        more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
        problems.append((("shards",), f"creature {json.dumps(missing[0])} is in no shard{more}"))
    return problems
