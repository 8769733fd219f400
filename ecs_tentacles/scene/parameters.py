"""The parameter table: each tentacle and creature parameter, defined once, in the schema.

A parameter is a property of the scene schema annotated with `x-parameter`:

    "strength": {"type": "number", "minimum": 0, "maximum": 1000, "default": 25.0,
                 "x-parameter": {"column": "motors.strength", "taper": "scale",
                                 "units": "N m/rad", "label": "strength (kp)",
                                 "slider": {"order": 2, "digits": 1, "log": true}}}

The property gives the scene key, default and range (`minimum`/`maximum`, or `enum`:
the stored code of a choice is its index there). The annotation gives the rest:

* `column`: the store column it fills, `<store>.<field>` against the world's stores
  by name (`motors.strength`, `locomotion.tentacles.speed`: `world.stores`); a
  parameter stored per creature (`creatures.*`, `locomotion.creatures.*`) is
  creature-wide at run time;
* `units`: the scene's units. A key ending in `_deg` is degrees in the scene and
  radians in code (stores, `world.resource(Locomotion)`), whose name drops the `_deg`;
* `taper`: a column of the same store the value is multiplied by, row by row
  (`scale`: each link's construction scale);
* `at_most`: a column that caps it, row by row: a field of the same store, or
  `<store>.<field>` of another store with the same rows (drivers: `creatures.tentacles`,
  the tentacle count);
* `runtime`: false when `world.resource(Locomotion).set` cannot change it (read at compile);
* `label`, and `slider` (`order`, `digits`, `log`): how the HUD shows it.

`parameters(schema)` walks whatever schema dict it is given (the bundled one by
default, or one assembled from plugins' fragments) and finds annotated properties
wherever they sit; a parameter's section is the name of the object holding it
(`tentacles`, `locomotion`). Build code fills store columns with `apply_parameters`;
`world.resource(Locomotion)`, the HUD and the creator read the same records.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.scene.ranges import Range, schema_objects, schema_range
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.scene.validate import format_path

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

ANNOTATION = "x-parameter"
DEGREE = math.radians(1.0)  # one scene degree in code's radians
_KEYS = {"column", "units", "label", "taper", "at_most", "runtime", "slider"}
_SLIDER_KEYS = {"order", "digits", "log"}


@dataclass(frozen=True)
class Slider:
    """How the HUD shows a parameter: its place among the sliders, digits, log scale."""

    order: int
    digits: int
    log: bool = False


@dataclass(frozen=True)
class Parameter:
    """One scene parameter: where it is in the scene, where it is stored, how it is shown.

    `range` is in code units (radians for `_deg` keys); `choices` replaces it for
    enumerations, whose stored value is the choice's index.
    """

    section: str
    key: str
    store: str
    field: str
    units: str
    label: str
    range: Range | None
    choices: tuple[str, ...] = ()
    factor: float = 1.0  # code value = scene value x factor
    taper: str | None = None
    at_most: str | None = None
    runtime: bool = True
    slider: Slider | None = None

    @property
    def api(self) -> str:
        """The name scripts use (`world.resource(Locomotion).set(..., target_angle=0.5)`)."""
        return self.key.removesuffix("_deg")

    @property
    def column(self) -> str:
        return f"{self.store}.{self.field}"

    def code(self, choice: object) -> int:
        """The stored code of one of `choices` (gait "coordinated" -> 1)."""
        return self.choices.index(choice)

    def from_scene(self, value: object) -> float | str:
        """A scene value in code units (radians for `_deg` keys); a choice stays its name."""
        if self.choices and isinstance(value, str):
            return value
        if not self.choices and isinstance(value, int | float):
            return value * self.factor
        raise TypeError(f"{self.section}.{self.key}: not a valid scene value: {value!r}")

    def to_api(self, stored: float) -> float | str:
        """A stored value as `world.resource(Locomotion).get` reports it (before any taper)."""
        if self.choices:
            return self.choices[int(stored)]
        return int(stored) if self.range and self.range.integer else float(stored)

    def check(self, value: object) -> float | str:
        """An API value (code units) if allowed, else a ValueError naming the parameter."""
        if self.choices:
            if not isinstance(value, str) or value not in self.choices:
                allowed = ", ".join(self.choices)
                raise ValueError(f"{self.api}: must be one of {allowed}, got {value!r}")
            return value
        assert self.range is not None
        return self.range.check(self.api, value)

    def cap(self, world: Host) -> np.ndarray:
        """The `at_most` column of `world` (its rows line up with this parameter's store)."""
        assert self.at_most is not None
        store, _, field = self.at_most.rpartition(".")
        column: np.ndarray = getattr(world.stores[store or self.store], field)
        return column

    def write(self, world: Host, rows: int | np.ndarray, value: object) -> None:
        """Store an API value at `rows` of its column: tapered and capped by its row's columns."""
        store = world.stores[self.store]
        if self.choices:
            stored: float | np.ndarray = self.code(value)
        elif isinstance(value, int | float):
            stored = value
        else:
            raise TypeError(f"{self.api}: must be a number, got {value!r}")
        if self.taper:
            stored = stored * getattr(store, self.taper)[rows]
        if self.at_most:
            stored = np.minimum(stored, self.cap(world)[rows])
        getattr(store, self.field)[rows] = stored


def _annotated(
    schema: Mapping[str, object],
) -> Iterator[tuple[str, str, Mapping[str, object], str]]:
    """(section, key, property schema, JSON path) of every annotated property of `schema`."""
    for section, node, path in schema_objects(schema):
        properties = node["properties"]  # (a Mapping: `schema_objects` says so)
        for key, spec in properties.items() if isinstance(properties, Mapping) else ():
            if isinstance(spec, Mapping) and ANNOTATION in spec:
                yield section, key, spec, format_path([*path, "properties", key])


def _parameter(section: str, key: str, spec: Mapping[str, object], where: str) -> Parameter:
    meta = spec[ANNOTATION]
    where = f"{where}.{ANNOTATION}"
    if not isinstance(meta, Mapping):
        raise ValueError(f"{where}: must be an object")
    unknown = set(meta) - _KEYS
    if unknown or not {"column", "units", "label"} <= set(meta):
        problem = f"unknown key {sorted(unknown)[0]!r}" if unknown else "needs column, units, label"
        raise ValueError(f"{where}: {problem}")
    store, _, field = str(meta["column"]).rpartition(".")
    if not store or not field:
        raise ValueError(f"{where}: column must be <store>.<field>, got {meta['column']!r}")
    degrees = key.endswith("_deg")
    if degrees != (meta["units"] == "deg"):
        raise ValueError(f"{where}: units must be 'deg' exactly when the key ends in _deg")
    slider = meta.get("slider")
    if slider is not None and set(slider) - _SLIDER_KEYS:
        raise ValueError(f"{where}.slider: unknown key {sorted(set(slider) - _SLIDER_KEYS)[0]!r}")
    factor = DEGREE if degrees else 1.0
    enum = spec.get("enum", ())
    choices = tuple(enum) if isinstance(enum, list | tuple) else ()
    return Parameter(
        section=section,
        key=key,
        store=store,
        field=field,
        units=meta["units"],
        label=meta["label"],
        range=None if choices else schema_range(spec).scaled(factor),
        choices=choices,
        factor=factor,
        taper=meta.get("taper"),
        at_most=meta.get("at_most"),
        runtime=meta.get("runtime", True),
        slider=Slider(**slider) if slider is not None else None,
    )


def read_parameters(schema: Mapping[str, object]) -> tuple[Parameter, ...]:
    """Every annotated parameter of `schema`, in document order; each column at most once."""
    table: list[Parameter] = []
    seen: dict[tuple[str, str], str] = {}
    for section, key, spec, where in _annotated(schema):
        parameter = _parameter(section, key, spec, where)
        for kind, name in (("column", parameter.column), ("scene key", f"{section}.{key}")):
            if (kind, name) in seen:
                raise ValueError(f"{where}: {kind} {name} is already defined at {seen[kind, name]}")
            seen[kind, name] = where
        table.append(parameter)
    return tuple(table)


@functools.cache
def parameters() -> tuple[Parameter, ...]:
    """The parameters of the bundled scene schema (read once)."""
    return read_parameters(load_schema())


def parameter(section: str, key: str, table: Iterable[Parameter] | None = None) -> Parameter:
    """The parameter at scene key `<section>.<key>` (`"tentacles", "strength"`)."""
    for found in parameters() if table is None else table:
        if (found.section, found.key) == (section, key):
            return found
    raise KeyError(f"{section}.{key}: not a parameter of the scene schema")


def apply_parameters(
    world: Host,
    section: str,
    entry: Mapping[str, object],
    rows: Mapping[str, int | np.ndarray],
    table: Sequence[Parameter] | None = None,
) -> None:
    """Fill store columns from a scene entry (defaults applied) of `section`, at `rows`.

    `rows` maps store names (`world.stores`) to the rows to fill; parameters of other
    stores are left for another call (a tentacle's links are built before its tentacle
    row, and features fill their own stores):

        apply_parameters(world, "tentacles", params, {"motors": link_rows})
        apply_parameters(world, "locomotion", spec["locomotion"], {"locomotion.creatures": row})
    """
    for found in parameters() if table is None else table:
        if found.section == section and found.store in rows and found.key in entry:
            value = entry[found.key]
            found.write(world, rows[found.store], found.from_scene(value))
