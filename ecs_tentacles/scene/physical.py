"""Load-time physical checks: refuse a scene that cannot build a stable, finite world.

Run by `ecs_tentacles.scene.load.load_scene` on a schema-valid scene with defaults
filled in, before anything is built. The creatures are laid out by the same
construction code as the build (`ecs_tentacles.scene.construction.creature_layout`), and
each problem is one line naming its JSON path, like the validator's:

* the physics step `1 / (fps * substeps)` longer than `MAX_SUBSTEP` (servos at the
  schema's highest strength and contacts are stable up to it);
* gravity pointing up, tilted more than 45 degrees (creatures tumble over and fall away
  ever faster), or pulling sideways harder than the ground's friction holds: the
  creatures would fall or slide away ever faster (sliding at 100 m/s blew contacts up);
* a body too light for MuJoCo (it refuses masses and inertias under mjMINVAL = 1e-15;
  we keep `MIN_MASS` and `MIN_INERTIA` a thousand times above that), or a link shorter
  than `MIN_LENGTH` (MuJoCo: "fromto points too close"), or a mantle flatter than
  `MIN_FLATNESS` of its radius (MuJoCo: "inertia must satisfy A + B >= C");
* needle-like links (longer than `MAX_SLENDERNESS` radii) and a mantle more than
  `MAX_MASS_RATIO` times heavier or lighter than its tentacles;
* a servo damped less than `strength x step` (`scene.ranges.damping_floor`);
* a creature starting inside the ground (it would be shot out in the first frame);
* creatures whose built bodies interpenetrate; with `physics.separate_overlaps` they
  are moved apart instead (the scene's positions are updated in place).
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

from ecs_tentacles.scene.construction import (
    CreatureLayout,
    capsule_mass_inertia,
    cylinder_mass_inertia,
)
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.scene.overlap import Bodies, Overlap, find_overlaps, separate
from ecs_tentacles.scene.ranges import damping_floor
from ecs_tentacles.scene.scene_spec import PhysicsSpec
from ecs_tentacles.scene.spec import CreatureSpec, TentaclesSpec, creature_specs
from ecs_tentacles.scene.validate import format_path

log = logging.getLogger(__name__)

MAX_SUBSTEP = 1.0 / 400.0  # s; the stiffest servos (strength 1000) shook apart beyond it
MIN_MASS = 1e-12  # kg
MIN_INERTIA = 1e-12  # kg m^2
MIN_LENGTH = 1e-6  # m; MuJoCo needs a capsule's ends apart
# Height / radius of the flattest mantle: MuJoCo's check that the principal inertias form a
# triangle (A + B >= C) failed on rounding for discs near 1e-10 thin, and a 22 mm disc
# 3 micrometres thick still spun itself apart within 15 s.
MIN_FLATNESS = 0.01
# A link longer than this many radii is a needle: 10 m x 2.5 cm links flailed under
# sideways gravity fast enough to blow the contacts up.
MAX_SLENDERNESS = 100.0
# Mantle mass / tentacle mass beyond this either way made the mass matrix too
# ill-conditioned: a 2 mg mantle on 400 kg links, a 1000 t mantle on 0.6 kg links.
MAX_MASS_RATIO = 1e4
SHAPE_KEYS = ("links", "link_length", "link_radius", "end_scale")
Path = tuple[str | int, ...]


def physically_checked(
    scene: dict[str, object],
    prefix: str = "",
    plane: bool = True,
    layouts: Layouts | None = None,
) -> dict[str, object]:
    """`scene` (creatures moved apart if it asks), or SceneError with every physical problem.

    `prefix` starts each problem line (the loader passes `"<file>: "`); `plane` and
    `layouts`: as `physical_problems`.
    """
    problems = physical_problems(scene, plane, layouts)
    if problems:
        raise SceneError([prefix + problem for problem in problems])
    return scene


def physical_problems(
    scene: dict[str, Any], plane: bool = True, layouts: Layouts | None = None
) -> list[str]:
    """Every physical problem of a schema-valid scene (defaults filled in), one line each.

    `plane`: the ground under the creatures is the plane z = 0, so no part may start
    below it; False when a plugin shapes the ground (`Plugin.shapes_ground`), which then
    checks that itself.

    With `physics.separate_overlaps` true, overlapping creatures are moved apart by
    changing their `position` in `scene`; only a crowd that cannot be pulled apart is
    then a problem.

    Each creature's layout comes from `layouts` (the load's: the build reuses them),
    worked out there the first time.
    """
    layouts = Layouts() if layouts is None else layouts
    physics = scene["physics"]
    problems: list[tuple[Path, str]] = _timestep_problems(physics) + _gravity_problems(physics)
    bodies: list[Bodies] = []  # each creature's capsules
    for i, creature in enumerate(creature_specs(scene)):
        problems += creature_problems(("creatures", i), creature, physics, plane, layouts)
        bodies.append(Bodies(*layouts.on_plane(creature).capsules()))
    if not problems:
        problems += _overlap_problems(scene, bodies)
    return [f"{format_path(path)}: {message}" for path, message in problems]


def creature_problems(
    where: Path,
    creature: CreatureSpec,
    physics: PhysicsSpec,
    plane: bool = True,
    layouts: Layouts | None = None,
) -> list[tuple[Path, str]]:
    """The physical problems of one creature entry at `where` (`("creatures", 2)`) in a
    scene of these `physics` settings: too light, needles, servos that shake, inside
    the plane (`plane`; `physical_problems`). Its layout comes from `layouts`."""
    layout = (Layouts() if layouts is None else layouts).on_plane(creature)
    step = _step(physics)
    key = _body_key(creature, layout, step)
    found = _BODY_PROBLEMS.get(key)
    if found is None:  # a body plan not seen yet (a uniform crowd has one)
        found = _body_problems(creature, layout, step)
        if len(_BODY_PROBLEMS) > 1024:
            _BODY_PROBLEMS.clear()
        _BODY_PROBLEMS[key] = found
    problems = [((*where, *path), message) for path, message in found]
    if plane:  # a plugin that shapes the ground checks its own
        problems += _below_ground(where, layout)
    return problems


# a body plan's problems (`_body_key`), paths from the creature: worked out once per plan
_BODY_PROBLEMS: dict[tuple[object, ...], list[tuple[Path, str]]] = {}


def _body_key(creature: CreatureSpec, layout: CreatureLayout, step: float) -> tuple[object, ...]:
    """Everything `_body_problems` reads: the mantle, each tentacle's shape, density and
    servo, which overrides set a shape or a servo (problem paths name them), the step."""
    mantle = creature["mantle"]
    overrides = tuple(
        (o["index"], any(k in o for k in SHAPE_KEYS), "strength" in o or "damping" in o)
        for o in creature["tentacles"]["overrides"]
    )
    return (
        step,
        (mantle["radius"], mantle["height"], mantle["density"]),
        tuple(
            (
                p["link_length"],
                p["link_radius"],
                p["links"],
                p["end_scale"],
                p["density"],
                p["strength"],
                p["damping"],
            )
            for p in layout.params
        ),
        overrides,
    )


def _body_problems(
    creature: CreatureSpec, layout: CreatureLayout, step: float
) -> list[tuple[Path, str]]:
    """`creature_problems` of its body plan alone (not where it stands), paths from the
    creature (`("mantle",)`)."""
    where: Path = ()
    weights = [  # (links, 2) masses and inertias per tentacle, for both checks below
        capsule_mass_inertia(shape.lengths, shape.radii, params["density"])
        for params, shape in zip(layout.params, layout.shapes, strict=True)
    ]
    # a body too light says enough; its proportions would be refused too
    problems = _light_bodies(where, creature, layout, weights) or _proportion_problems(
        where, creature, layout, weights
    )
    return problems + _servo_problems(where, creature, layout, step)


def _step(physics: PhysicsSpec) -> float:
    """The physics step 1 / (fps * substeps), in seconds."""
    return float(1.0 / (physics["fps"] * physics["substeps"]))


def _timestep_problems(physics: PhysicsSpec) -> list[tuple[Path, str]]:
    fps, step = physics["fps"], _step(physics)
    if step <= MAX_SUBSTEP * (1 + 1e-9):
        return []
    needed = math.ceil(1.0 / (MAX_SUBSTEP * fps) - 1e-9)
    message = (
        f"a physics step of 1 / (fps * substeps) = {1e3 * step:.3g} ms is longer than"
        f" {1e3 * MAX_SUBSTEP:g} ms, beyond which servos and contacts shake apart;"
        f" at fps {fps:g} use substeps >= {needed}"
    )
    return [(("physics", "substeps"), message)]


def _gravity_problems(physics: PhysicsSpec) -> list[tuple[Path, str]]:
    x, y, z = (float(g) for g in physics["gravity"])
    sideways, friction = math.hypot(x, y), physics["ground_friction"]
    if z > 0:
        message = f"points up (z = {z:g}): creatures would fall away from the ground; use z <= 0"
    elif sideways > -z:
        message = (
            f"tilts more than 45 degrees (sideways {sideways:.3g} m/s^2 against z = {z:g}):"
            " creatures would tumble over and fall ever faster; keep |sideways| <= |z|"
        )
    elif sideways > friction * -z:
        message = (
            f"pulls sideways ({sideways:.3g} m/s^2) harder than ground_friction {friction:g}"
            f" holds against z = {z:g} ({friction * -z:.3g} m/s^2): creatures would slide ever"
            " faster; tilt it less or raise ground_friction"
        )
    else:
        return []
    return [(("physics", "gravity"), message)]


def _tentacle_path(where: Path, tentacles: TentaclesSpec, k: int) -> Path:
    """Where tentacle `k`'s shape comes from: its override if that sets one, else the creature."""
    for j, override in enumerate(tentacles["overrides"]):
        if override["index"] == k and any(key in override for key in SHAPE_KEYS):
            return (*where, "tentacles", "overrides", j)
    return (*where, "tentacles")


def _light_bodies(
    where: Path, creature: CreatureSpec, layout: CreatureLayout, weights: list[np.ndarray]
) -> list[tuple[Path, str]]:
    problems: list[tuple[Path, str]] = []
    mantle = creature["mantle"]
    mass, inertia = cylinder_mass_inertia(mantle["radius"], mantle["height"], mantle["density"])
    if mantle["height"] < MIN_FLATNESS * mantle["radius"]:
        problems.append(
            (
                (*where, "mantle"),
                f"is too flat to simulate (height {mantle['height']:.2g} m, under"
                f" {MIN_FLATNESS:g} x its radius {mantle['radius']:.2g} m); raise height",
            )
        )
    elif mass < MIN_MASS or inertia < MIN_INERTIA:
        problems.append(
            (
                (*where, "mantle"),
                f"too light to simulate ({_weights(mass, inertia)});"
                " raise radius, height or density",
            )
        )
    seen: set[Path] = set()
    for k, (shape, tentacle) in enumerate(zip(layout.shapes, weights, strict=True)):
        path = _tentacle_path(where, creature["tentacles"], k)
        light = (tentacle[:, 0] < MIN_MASS) | (tentacle[:, 1] < MIN_INERTIA)
        short = shape.lengths < MIN_LENGTH
        if path in seen or not (light.any() or short.any()):
            continue
        seen.add(path)
        if short.any():
            link = int(np.flatnonzero(short)[0])
            why = (
                f"is too short to simulate ({shape.lengths[link]:.2g} m; at least {MIN_LENGTH:g} m)"
            )
            advice = "raise link_length or end_scale"
        else:
            link = int(np.flatnonzero(light)[0])
            why = f"is too light to simulate ({_weights(*tentacle[link])})"
            advice = "raise link_radius, end_scale or density"
        problems.append((path, f"link {link} of tentacle {k} {why}; {advice}"))
    return problems


def _proportion_problems(
    where: Path, creature: CreatureSpec, layout: CreatureLayout, weights: list[np.ndarray]
) -> list[tuple[Path, str]]:
    problems: list[tuple[Path, str]] = []
    for k, params in enumerate(layout.params):
        slender = params["link_length"] / params["link_radius"]
        if slender > MAX_SLENDERNESS:
            problems.append(
                (
                    _tentacle_path(where, creature["tentacles"], k),
                    f"links {slender:.3g} times longer than their radius (at most"
                    f" {MAX_SLENDERNESS:g}) are needles, not tentacle links; shorten link_length"
                    " or thicken link_radius",
                )
            )
            break
    mantle = creature["mantle"]
    mantle_mass, _ = cylinder_mass_inertia(mantle["radius"], mantle["height"], mantle["density"])
    tentacles = sum(float(tentacle[:, 0].sum()) for tentacle in weights)
    ratio = mantle_mass / tentacles
    if not 1.0 / MAX_MASS_RATIO <= ratio <= MAX_MASS_RATIO:
        problems.append(
            (
                (*where, "mantle"),
                f"weighs {mantle_mass:.3g} kg against {tentacles:.3g} kg of tentacles; keep the"
                f" ratio within {MAX_MASS_RATIO:g} either way (change the mantle's or the"
                " tentacles' size or density)",
            )
        )
    return problems


def _servo_problems(
    where: Path, creature: CreatureSpec, layout: CreatureLayout, step: float
) -> list[tuple[Path, str]]:
    problems: list[tuple[Path, str]] = []
    seen: set[Path] = set()
    for k, params in enumerate(layout.params):
        least = damping_floor(params["strength"], step)
        if params["damping"] >= least:
            continue
        path: Path = (*where, "tentacles", "damping")
        for j, override in enumerate(creature["tentacles"]["overrides"]):
            if override["index"] == k and ("strength" in override or "damping" in override):
                path = (*where, "tentacles", "overrides", j, "damping")
        if path in seen:
            continue
        seen.add(path)
        problems.append(
            (
                path,
                f"{params['damping']:g} is below strength x physics step ({params['strength']:g}"
                f" x {1e3 * step:.3g} ms = {least:.3g}): a servo this stiff and this little"
                f" damped shakes its links apart; raise damping to >= {least:.3g}, lower"
                " strength or add substeps",
            )
        )
    return problems


def _weights(mass: float, inertia: float) -> str:
    return (
        f"mass {mass:.2g} kg, inertia {inertia:.2g} kg m^2;"
        f" at least {MIN_MASS:g} kg and {MIN_INERTIA:g} kg m^2"
    )


def _below_ground(where: Path, layout: CreatureLayout) -> list[tuple[Path, str]]:
    thickest = max(float(shape.radii.max()) for shape in layout.shapes)
    lowest = layout.origin[2] - thickest
    if lowest >= -1e-9:
        return []
    message = (
        f"the creature starts {_millimetres(-lowest)} inside the ground; give z >= {thickest:g}"
        " (its thickest link radius) or leave z out"
    )
    return [((*where, "position"), message)]


def _millimetres(metres: float) -> str:
    mm = 1e3 * metres
    return f"{mm:.0f} mm" if mm >= 1 else f"{mm:.2g} mm"


def _overlap_problems(scene: dict[str, Any], bodies: list[Bodies]) -> list[tuple[Path, str]]:
    if not scene["physics"]["separate_overlaps"]:
        advice = "move it or set physics.separate_overlaps"
        return [_overlap_line(overlap, advice) for overlap in find_overlaps(bodies)]
    offsets, left = separate(bodies)
    for i, offset in enumerate(offsets):
        if offset.any():
            creature = scene["creatures"][i]
            position = [float(v) for v in creature["position"]]
            creature["position"] = [p + float(d) for p, d in zip(position, offset, strict=False)]
            log.info("creatures[%d] moved by %.3f m to clear overlaps", i, np.linalg.norm(offset))
    return [_overlap_line(o, "could not be moved apart; spread the creatures out") for o in left]


def _overlap_line(overlap: Overlap, advice: str) -> tuple[Path, str]:
    message = (
        f"overlaps creatures[{overlap.earlier}] ({overlap.what} interpenetrate by"
        f" {_millimetres(overlap.depth)} at build); {advice}"
    )
    return (("creatures", overlap.later), message)
