"""Scene rules for fur and emotion that the JSON Schema cannot express.

Called by `ecs_tentacles.scene.validate` on a schema-valid scene with defaults (and
presets) filled in; each problem is (JSON path, message).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

from ecs_tentacles.fur.controls import mirror_name

Path = tuple[str | int, ...]
Problem = tuple[Path, str]


def _where(path: Path) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else part)
    return out


def _keys_problems(keys: Sequence[Mapping[str, Any]], path: Path, value: str) -> list[Problem]:
    """Key times must increase; values must fit: 'point' (3 numbers) or 'unit' (0..1)."""
    problems: list[Problem] = []
    for k, key in enumerate(keys):
        if k and key["time"] <= keys[k - 1]["time"]:
            previous = keys[k - 1]["time"]
            problems.append(
                (
                    (*path, k, "time"),
                    f"must be > {previous} (the previous key's), got {key['time']}",
                )
            )
        got = key.get("value")
        if value == "position" and not (isinstance(got, list) and len(got) == 3):
            problems.append(
                ((*path, k, "value"), f"must be [x, y, z] for position, got {json.dumps(got)}")
            )
        elif value != "position" and not (
            isinstance(got, int | float) and not isinstance(got, bool) and 0 <= got <= 1
        ):
            problems.append(
                (
                    (*path, k, "value"),
                    f"must be a number in [0, 1] for {value}, got {json.dumps(got)}",
                )
            )
    return problems


def _fur_problems(fur: Mapping[str, Any], path: Path) -> list[Problem]:
    problems: list[Problem] = []
    names: dict[str, str] = {}  # control name -> who has it
    for c, control in enumerate(fur["controls"]):
        here: Path = (*path, "controls", c)
        owners = [(control["name"], "name", _where(here))]
        if control["mirror"] != "none":
            owners.append((mirror_name(control["name"]), "mirror", f"the twin of {_where(here)}"))
        for name, field, owner in owners:
            if name in names:
                problems.append(
                    ((*here, field), f'control name "{name}" is taken by {names[name]}')
                )
            else:
                names[name] = owner
        for t, track in enumerate(control["tracks"]):
            keys_path: Path = (*here, "tracks", t, "keys")
            problems += _keys_problems(track["keys"], keys_path, track["attribute"])
    for g, guide in enumerate(fur["guides"]):
        here = (*path, "guides", g)
        if "control" in guide and guide["control"] not in names:
            known = ", ".join(names)
            problems.append(
                ((*here, "control"), f'no control named "{guide["control"]}" (controls: {known})')
            )
        first, second = guide["points"][:2]
        if first == second:
            problems.append(((*here, "points"), "the first two points must differ"))
    return problems


def fur_problems(scene: Mapping[str, Any]) -> list[Problem]:
    """Every fur and emotion problem of a defaults-filled scene."""
    problems: list[Problem] = []
    for i, creature in enumerate(scene["creatures"]):
        if "fur" in creature:
            problems += _fur_problems(creature["fur"], ("creatures", i, "fur"))
    return problems
