"""Generated crowd scenes: N varied creatures on a jittered grid, crossing paths.

    scene = crowd_scene(256, seed=4, idle=0.2)       # a scene dict; load_scene accepts it
    write_crowd_scene(scene, "crowd.json")          # validated, written atomically

How a crowd is made, all from one `numpy.random.default_rng(seed)` (the same seed
gives the same JSON, byte for byte):

* Body plans ("species", default 8): 3 to 8 tentacles (the first six plans take
  8, 7, 6, 5, 4 and 3 in turn, so every count occurs), mantle radius and height,
  links per tentacle, first-link length and radius, end scale, and one or two
  tentacles per plan with their own shape (the schema's `tentacles.overrides`).
  Creatures share a few body plans, as a real crowd of a few species does, so a
  physics layer that compiles each morphology once compiles a handful of models.
  Servo strength and torque limit scale with the tentacle's weight x length.
  `uniform=True` makes every creature the default octopus (8 x 10 links, the
  schema's sizes) instead: one morphology, still with varied behaviour and fur.
* Per creature: heading, gait, crawl speed, travelling-wave settings, per-tentacle
  speed and wave changes (overrides that leave the shape alone), and for about a
  quarter of them fur (a preset with a small groom, so a 1,024 crowd stays cheap).
* Placement: a square grid centred on the origin, `spacing` apart, each position
  jittered. A creature's reach is its mantle radius + its longest tentacle + its
  thickest link radius. The default spacing is twice the largest reach in the crowd
  plus `CLEARANCE`; jitter per axis is at most a quarter of the spare room
  (spacing - 2 x largest reach) and at most `JITTER` x spacing, so no two
  creatures' reach circles overlap at build.
* Goals: each creature crawls to its position mirrored through the crowd's centre
  (plus a little jitter), so mirrored pairs meet head-on and the whole crowd
  crosses in the middle. A creature too close to the centre for that gets a goal
  one spacing away in a random direction. `idle` is the fraction of creatures (chosen
  at random) with no goal at all; they rest (no waves, no writhing), so they fall
  asleep (`ecs_tentacles.physics.sleep`) until another creature comes near.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, TypedDict

import numpy as np

from ecs_tentacles.creator.limits import default
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.scene.schema import core_schema

DEFAULT_SPECIES = 8
CLEARANCE = 0.4  # metres between the reach circles of two neighbours, before jitter
JITTER = 0.1  # largest jitter per axis, as a share of the spacing
FUR_SHARE = 0.25
FUR_PRESETS = ("hedgehog", "cat", "bird")
GROOM_COUNT = (16, 48)  # guides per furry creature: a look, not a hero groom
# The octopus defaults' size (8 x 10 links of 0.07 m, radius 0.025): strength 25, torque 20.
REFERENCE_WEIGHT_LENGTH = 0.025**2 * 0.7**2


class BodyPlan(TypedDict):
    """One species' body: its mantle and tentacles (creature entry keys), and the own
    shape of a few of its tentacles, by index."""

    mantle: dict[str, float]
    tentacles: dict[str, float]  # `count` and `links` whole
    shape_overrides: dict[int, dict[str, float]]


def max_creatures() -> int:
    """The most creatures a scene holds (the schema's `creatures.maxItems`)."""
    return int(core_schema()["properties"]["creatures"]["maxItems"])


def _r(value: float) -> float:
    """A JSON-friendly float: 4 decimals are a tenth of a millimetre."""
    return round(float(value), 4)


def _strength_factor(links: int, link_length: float, link_radius: float) -> float:
    """Servo strength relative to the octopus defaults: the tentacle's weight x length."""
    weight_length = link_radius**2 * (links * link_length) ** 2
    return float(np.clip(weight_length / REFERENCE_WEIGHT_LENGTH, 0.6, 2.5))


def _body_plan(rng: np.random.Generator, count: int) -> BodyPlan:
    """Mantle and tentacle shape of one species with `count` tentacles."""
    links = int(rng.integers(7, 12))
    link_length = rng.uniform(0.055, 0.085)
    link_radius = rng.uniform(0.019, 0.029)
    overrides: dict[int, dict[str, float]] = {}
    for index in rng.choice(count, size=int(rng.integers(1, 3)), replace=False):
        own_links = int(np.clip(links + rng.integers(-2, 3), 5, 13))
        own_length = _r(link_length * rng.uniform(0.85, 1.15))
        own_radius = _r(link_radius * rng.uniform(0.85, 1.1))
        overrides[int(index)] = {
            "links": own_links,
            "link_length": own_length,
            "link_radius": own_radius,
            "strength": _r(25.0 * _strength_factor(own_links, own_length, own_radius)),
        }
    factor = _strength_factor(links, link_length, link_radius)
    return {
        "mantle": {
            "radius": _r(rng.uniform(0.11, 0.19)),
            "height": _r(rng.uniform(0.15, 0.26)),
            "density": _r(rng.uniform(300.0, 500.0)),
        },
        "tentacles": {
            "count": count,
            "links": links,
            "link_length": _r(link_length),
            "link_radius": _r(link_radius),
            "end_scale": _r(rng.uniform(0.25, 0.4)),
            "strength": _r(25.0 * factor),
            "max_torque": _r(20.0 * factor),
        },
        "shape_overrides": overrides,
    }


def _octopus() -> BodyPlan:
    """The schema's default creature (8 x 10 links) as a body plan."""
    mantle = {key: default("mantle", key) for key in ("radius", "height", "density")}
    keys = ("count", "links", "link_length", "link_radius", "end_scale", "strength", "max_torque")
    tentacles = {key: default("tentacles", key) for key in keys}
    return {"mantle": mantle, "tentacles": tentacles, "shape_overrides": {}}


def _species(rng: np.random.Generator, species: int) -> list[BodyPlan]:
    counts = [8 - k if k < 6 else int(rng.integers(3, 9)) for k in range(species)]
    return [_body_plan(rng, count) for count in counts]


def _creature(rng: np.random.Generator, name: str, plan: BodyPlan) -> dict[str, object]:
    """One creature of body plan `plan`, with its own behaviour and maybe fur."""
    count = int(plan["tentacles"]["count"])
    overrides = {k: dict(v) for k, v in plan["shape_overrides"].items()}
    for index in rng.choice(count, size=int(rng.integers(0, 3)), replace=False):
        overrides.setdefault(int(index), {}).update(
            speed=_r(rng.uniform(0.8, 1.25)), wave_frequency=_r(rng.uniform(0.4, 0.9))
        )
    tentacles: dict[str, object] = {**plan["tentacles"]}
    tentacles.update(
        wave_amplitude_deg=_r(rng.uniform(3.0, 9.0)),
        wave_frequency=_r(rng.uniform(0.4, 0.8)),
        writhe=_r(rng.uniform(0.15, 0.45)),
        overrides=[{"index": k, **overrides[k]} for k in sorted(overrides)],
    )
    creature: dict[str, object] = {
        "name": name,
        "position": [0.0, 0.0],
        "heading_deg": _r(rng.uniform(-180.0, 180.0)),
        "mantle": dict(plan["mantle"]),
        "tentacles": tentacles,
        "locomotion": {
            "gait": "cyclic" if rng.random() < 0.25 else "coordinated",
            "speed": _r(rng.uniform(0.85, 1.2)),
        },
    }
    if rng.random() < FUR_SHARE:
        creature["fur"] = {
            "preset": FUR_PRESETS[int(rng.integers(len(FUR_PRESETS)))],
            "groom": {
                "count": int(rng.integers(GROOM_COUNT[0], GROOM_COUNT[1] + 1)),
                "seed": int(rng.integers(0, 2**31)),
            },
        }
    return creature


def species_creatures(count: int = DEFAULT_SPECIES, seed: int = 0) -> list[dict[str, object]]:
    """One creature of each of the generator's first `count` species (the bodies a crowd
    mixes), named `species1` ..., at the origin: the director's palette lists them."""
    plans = _species(np.random.default_rng(seed), count)
    return [
        _creature(np.random.default_rng([seed, k]), f"species{k}", plan)
        for k, plan in enumerate(plans, start=1)
    ]


def _plan_reach(plan: BodyPlan) -> float:
    """`creature_reach` of every creature of `plan`: their own overrides keep its shape."""
    overrides = [{"index": k, **shape} for k, shape in plan["shape_overrides"].items()]
    tentacles = {**plan["tentacles"], "overrides": overrides}
    return creature_reach({"mantle": plan["mantle"], "tentacles": tentacles})


def grid_shape(n: int) -> tuple[int, int]:
    """(columns, rows) of the squarest grid that holds `n` creatures."""
    columns = math.ceil(math.sqrt(n))
    return columns, math.ceil(n / columns)


def crowd_scene(
    n: int,
    seed: int = 0,
    spacing: float | None = None,
    *,
    idle: float = 0.0,
    species: int = DEFAULT_SPECIES,
    uniform: bool = False,
) -> dict[str, Any]:
    """A scene dict of `n` varied creatures crossing the crowd (see the module docstring).

    Raises ValueError naming the argument when `n` is outside [1, `max_creatures()`],
    `idle` is outside [0, 1],
    `species < 1`, or `spacing` is too small for the creatures' reach.
    """
    if n < 1:
        raise ValueError(f"N: must be >= 1, got {n}")
    if n > max_creatures():
        raise ValueError(f"N: must be <= {max_creatures()}, the most a scene holds, got {n}")
    if not 0.0 <= idle <= 1.0:
        raise ValueError(f"idle: must be in [0, 1], got {idle}")
    if species < 1:
        raise ValueError(f"species: must be >= 1, got {species}")
    rng = np.random.default_rng(seed)
    plans = [_octopus()] if uniform else _species(rng, species)
    species = len(plans)
    plan_of = rng.permutation(np.arange(n) % species)
    width = len(str(n - 1))
    creatures = [_creature(rng, f"c{i:0{width}d}", plans[p]) for i, p in enumerate(plan_of)]
    largest = max(_plan_reach(plans[p]) for p in sorted(set(plan_of.tolist())))
    least = 2.0 * largest
    if spacing is None:
        spacing = least + CLEARANCE
    elif not math.isfinite(spacing) or spacing < least:
        raise ValueError(
            f"spacing: must be >= {least:.3f} m (twice the largest creature reach), got {spacing}"
        )
    jitter = min(0.25 * (spacing - least), JITTER * spacing)
    columns, rows = grid_shape(n)
    cells = np.arange(n)
    grid = np.stack([cells % columns - 0.5 * (columns - 1), cells // columns - 0.5 * (rows - 1)])
    positions = grid.T * spacing + rng.uniform(-jitter, jitter, size=(n, 2))
    goals = -positions + rng.uniform(-0.1, 0.1, size=(n, 2)) * spacing
    idle_ones = set(rng.choice(n, size=round(idle * n), replace=False).tolist())
    for i, creature in enumerate(creatures):
        angle = rng.uniform(0.0, 2.0 * np.pi)
        if np.hypot(*(goals[i] - positions[i])) < spacing:
            goals[i] = positions[i] + spacing * np.array([np.cos(angle), np.sin(angle)])
        creature["position"] = [_r(v) for v in positions[i]]
        if i not in idle_ones:
            creature["goals"] = [{"position": [_r(v) for v in goals[i]]}]
        else:
            _rest(creature)
    return {
        "version": 1,
        "name": f"crowd_{n}",
        "description": (
            f"{n} generated creatures of {min(species, n)} body plan(s), {spacing:.2f} m apart on a"
            f" {columns} x {rows} grid, crawling across the crowd's centre"
            f" ({len(idle_ones)} idle; seed {seed})."
        ),
        "seed": seed,
        "creatures": creatures,
    }


def write_crowd_scene(scene: dict[str, object], path: str | os.PathLike[str]) -> None:
    """Validate `scene` (SceneError if it does not) and write it as JSON, atomically."""
    load_scene(scene)
    with atomic_output(path) as temporary:
        temporary.write_text(json.dumps(scene, indent=1) + "\n", encoding="utf-8")


def _rest(creature: dict[str, object]) -> None:
    """No goal, and tentacles that lie still: no travelling waves, no writhing."""
    tentacles = creature.setdefault("tentacles", {})
    if not isinstance(tentacles, dict):
        raise TypeError(f"{creature.get('name')}: tentacles is an object, not {tentacles!r}")
    for part in (tentacles, *tentacles.get("overrides", [])):
        for key in ("wave_amplitude_deg", "writhe"):
            if key in part or part is tentacles:
                part[key] = 0
