"""JSON as the standard library parses it, as a type: `JsonValue` and `JsonObject`.

    data: JsonValue = json.loads(text)
    if isinstance(data, dict):          # JsonObject: read its keys, narrowing each
        name = data.get("name")

Reads nothing, writes nothing. For data whose shape the project knows, the
TypedDicts say more (`scene.spec`, `scene.scene_spec`); these are for what only the
JSON grammar describes: a plugin's own config, a header written back as it was read.
"""

from __future__ import annotations

from typing import TypeAlias

JsonValue: TypeAlias = dict[str, "JsonValue"] | list["JsonValue"] | str | int | float | bool | None
JsonObject: TypeAlias = dict[str, JsonValue]
