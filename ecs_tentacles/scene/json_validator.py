"""The JSON Schema validator scenes are checked with: Draft 2020-12, stricter where a
scene needs it.

* `integer` means written as an integer (`8`, not `8.0`);
* `number` means a finite number: a scene given as Python data (`World.from_scene(dict)`,
  `World.spawn`) can hold `nan` or `inf`, which pass every numeric bound;
* `pattern` reads `$` as the end of the text, as JSON Schema (ECMA 262) does; Python's
  `$` also matches before a trailing newline (`"octo\\n"` passed as a name).

`validator_for(schema)` keeps one validator per assembled schema object.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Iterator
from typing import Any

from jsonschema import Draft202012Validator, ValidationError, validators


def _is_integer(checker: object, value: object) -> bool:
    """JSON Schema calls 8.0 an integer; a scene's counts and seeds must be written 8."""
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(checker: object, value: object) -> bool:
    """A finite number: NaN compares false with every bound, so a range cannot refuse it."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return isinstance(value, int) or math.isfinite(value)


@functools.lru_cache(maxsize=256)
def ecma_pattern(pattern: str) -> re.Pattern[str]:
    """`pattern` as JSON Schema (ECMA 262) reads it: `$` is the end of the text.

    Python's `$` also matches before a trailing newline, which let `"octo\\n"` pass as a
    name; here every `$` outside a character class becomes `\\Z`.
    """
    out, escaped, in_class = [], False, False
    for char in pattern:
        if escaped:
            escaped = False
        elif char == "\\":
            escaped = True
        elif char == "[":
            in_class = True
        elif char == "]":
            in_class = False
        elif char == "$" and not in_class:
            char = r"\Z"
        out.append(char)
    return re.compile("".join(out))


def _pattern(validator: Any, pattern: str, instance: object, schema: object) -> Iterator[Any]:
    if isinstance(instance, str) and not ecma_pattern(pattern).search(instance):
        yield ValidationError(f"{instance!r} does not match {pattern!r}")


StrictValidator = validators.extend(
    Draft202012Validator,
    validators={"pattern": _pattern},
    type_checker=Draft202012Validator.TYPE_CHECKER.redefine_many(
        {"integer": _is_integer, "number": _is_number}
    ),
)


_VALIDATORS: dict[int, tuple[dict[str, Any], Any]] = {}  # id -> (schema kept alive, validator)


def validator_for(schema: dict[str, Any]) -> Any:
    """A validator per schema object (assembled schemas are cached, so this is too)."""
    found = _VALIDATORS.get(id(schema))
    if found is None or found[0] is not schema:
        if len(_VALIDATORS) > 64:
            _VALIDATORS.clear()
        found = _VALIDATORS[id(schema)] = (schema, StrictValidator(schema))
    return found[1]
