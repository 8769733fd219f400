"""The JSON Schema validator scenes are checked with: Draft 2020-12, stricter where a
scene needs it.

* `integer` means written as an integer (`8`, not `8.0`);
* `number` means a finite number: a scene given as Python data (`World.from_scene(dict)`,
  `World.spawn`) can hold `nan` or `inf`, which pass every numeric bound;
* `pattern` reads `$` as the end of the text, as JSON Schema (ECMA 262) does; Python's
  `$` also matches before a trailing newline (`"octo\\n"` passed as a name);
* a long array of plain numbers (`items` a number schema with bounds only, such as a
  heightfield's rows) is checked at once with numpy; only the items that fail are then
  looked at one by one, for the usual messages (a 1024 x 1024 `heights` took 31 s).

`validator_for(schema)` keeps one validator per assembled schema object.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Iterator
from typing import Any, cast

import numpy as np
from jsonschema import Draft202012Validator, ValidationError, _keywords, validators


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


_STANDARD_ITEMS = cast("Callable[..., Iterator[Any]]", _keywords.items)  # stubs say None
FAST_ITEMS = 64  # arrays of numbers at least this long are checked with numpy
_PLAIN_NUMBER = {"type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"}
_PLAIN_NUMBER |= {"description", "default", "title"}


def _failing_numbers(values: list[Any], schema: dict[str, Any]) -> np.ndarray | None:
    """Indices of `values` that are not finite numbers within `schema`'s bounds, found at
    once; None when the list holds anything but ints and floats (looked at one by one)."""
    kinds = set(map(type, values))
    if not kinds <= {int, float}:  # bool and numpy scalars are other types
        return None
    try:
        array = np.asarray(values, dtype=np.float64)
    except OverflowError:  # an int past a float's range
        return None
    ok = np.isfinite(array)
    if int in kinds and np.abs(array[ok]).max(initial=0.0) >= 2.0**53:
        return None  # ints a float could round into range
    with np.errstate(invalid="ignore"):
        if "minimum" in schema:
            ok &= array >= schema["minimum"]
        if "maximum" in schema:
            ok &= array <= schema["maximum"]
        if "exclusiveMinimum" in schema:
            ok &= array > schema["exclusiveMinimum"]
        if "exclusiveMaximum" in schema:
            ok &= array < schema["exclusiveMaximum"]
    return np.flatnonzero(~ok)


def _items(validator: Any, items: Any, instance: object, schema: Any) -> Iterator[Any]:
    """`items`, with long arrays of plain numbers checked at once (see the module's notes)."""
    if (
        isinstance(instance, list)
        and len(instance) >= FAST_ITEMS
        and isinstance(items, dict)
        and items.get("type") == "number"
        and items.keys() <= _PLAIN_NUMBER
        and not schema.get("prefixItems")
    ):
        failing = _failing_numbers(instance, items)
        if failing is not None:
            for index in failing.tolist():
                yield from validator.descend(instance=instance[index], schema=items, path=index)
            return
    yield from _STANDARD_ITEMS(validator, items, instance, schema)


StrictValidator = cast(Any, validators.extend)(  # jsonschema leaves extend untyped
    Draft202012Validator,
    validators={"pattern": _pattern, "items": _items},
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
