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

import math
from collections.abc import Callable, Iterator, Mapping
from typing import TYPE_CHECKING, cast

import numpy as np
from jsonschema import Draft202012Validator, ValidationError, _keywords, validators

from ecs_tentacles.scene.plain_pass import LONG_NUMBERS, ecma_pattern, passes_check

if TYPE_CHECKING:  # the class `validators.create` makes (the stubs' name; none at run time)
    from jsonschema.validators import _Validator


def _is_integer(checker: object, value: object) -> bool:
    """JSON Schema calls 8.0 an integer; a scene's counts and seeds must be written 8."""
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(checker: object, value: object) -> bool:
    """A finite number: NaN compares false with every bound, so a range cannot refuse it."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return isinstance(value, int) or math.isfinite(value)


def _pattern(
    validator: object, pattern: str, instance: object, schema: object
) -> Iterator[ValidationError]:
    if isinstance(instance, str) and not ecma_pattern(pattern).search(instance):
        yield ValidationError(f"{instance!r} does not match {pattern!r}")


# the stubs say None:
_STANDARD_ITEMS = cast("Callable[..., Iterator[ValidationError]]", _keywords.items)
FAST_ITEMS = LONG_NUMBERS  # arrays of numbers at least this long are checked with numpy
_PLAIN_NUMBER = {"type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"}
_PLAIN_NUMBER |= {"description", "default", "title"}


def _failing_numbers(values: list[object], schema: Mapping[str, object]) -> np.ndarray | None:
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
        low, high = schema.get("minimum"), schema.get("maximum")
        above, below = schema.get("exclusiveMinimum"), schema.get("exclusiveMaximum")
        if isinstance(low, (int, float)):
            ok &= array >= low
        if isinstance(high, (int, float)):
            ok &= array <= high
        if isinstance(above, (int, float)):
            ok &= array > above
        if isinstance(below, (int, float)):
            ok &= array < below
    return np.flatnonzero(~ok)


def _items(
    validator: _Validator, items: object, instance: object, schema: Mapping[str, object]
) -> Iterator[ValidationError]:
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
    if isinstance(instance, list) and isinstance(items, dict) and not schema.get("prefixItems"):
        check = passes_check(items, _resolver(validator))
        if check is not None:  # (the standard `items`, with the items that pass skipped)
            for index, item in enumerate(instance):
                if not check(item):
                    yield from validator.descend(instance=item, schema=items, path=index)
            return
    yield from _STANDARD_ITEMS(validator, items, instance, schema)


def _resolver(validator: _Validator) -> object:
    """The validator's `referencing` Resolver where it stands (for `$ref`s), or None."""
    return getattr(validator, "_resolver", None)


def _properties(
    validator: _Validator,
    properties: Mapping[str, Mapping[str, object] | bool],
    instance: object,
    schema: object,
) -> Iterator[ValidationError]:
    """`properties`, with values that surely pass their schema (`passes_check`) not
    descended into: jsonschema would find nothing there (a descent costs some
    microseconds each); any other value is descended into as usual, for the usual
    messages."""
    if not validator.is_type(instance, "object"):
        return
    assert isinstance(instance, dict)
    for name, subschema in properties.items():
        if name in instance:
            value = instance[name]
            check = passes_check(subschema, _resolver(validator))
            if check is not None and check(value):
                continue
            yield from validator.descend(value, subschema, path=name, schema_path=name)


_extend: Callable[..., type[_Validator]] = validators.extend  # the stubs leave it untyped
StrictValidator = _extend(
    Draft202012Validator,
    validators={"pattern": _pattern, "items": _items, "properties": _properties},
    type_checker=Draft202012Validator.TYPE_CHECKER.redefine_many(
        {"integer": _is_integer, "number": _is_number}
    ),
)


# id -> (schema kept alive, validator):
_VALIDATORS: dict[int, tuple[dict[str, object], _Validator]] = {}


def validator_for(schema: dict[str, object]) -> _Validator:
    """A validator per schema object (assembled schemas are cached, so this is too)."""
    found = _VALIDATORS.get(id(schema))
    if found is None or found[0] is not schema:
        if len(_VALIDATORS) > 64:
            _VALIDATORS.clear()
        found = _VALIDATORS[id(schema)] = (schema, StrictValidator(schema))
    return found[1]
