"""Bad scenes and the exact one-line problem each must produce (shared with the CLI tests)."""

from __future__ import annotations

from typing import Any

TENTACLE_KEYS = (
    "count, damping, density, end_scale, joint_limit_deg, link_length, link_radius, links, "
    "max_torque, overrides, speed, strength, suckers, target_angle_deg, twist, "
    "wave_amplitude_deg, wave_frequency, wavelength, writhe"
)
TOP_KEYS = (
    "$schema, avoidance, creatures, description, name, physics, plugins, render, seed, shards,"
    " systems, terrain, threats, version"
)
CREATURE_KEYS = (
    "avoid, emotion, fur, goals, heading_deg, locomotion, mantle, name, navigation, position,"
    " tentacles, threat"
)


def scene(*creatures: dict[str, Any], **top: Any) -> dict[str, Any]:
    """A version-1 scene with the given creatures (spread far apart unless positioned)."""
    placed = [{"position": [3 * i, 0], **c} for i, c in enumerate(creatures)]
    return {"version": 1, **({"creatures": placed} if creatures else {}), **top}


def fur_track(attribute: str, *keys: dict[str, Any]) -> dict[str, Any]:
    """A creature with one fur control `a` whose one track keys `attribute` with `keys`."""
    track = {"attribute": attribute, "keys": list(keys)}
    return {"fur": {"controls": [{"name": "a", "tracks": [track]}]}}


def tentacles(**fields: Any) -> dict[str, Any]:
    """A creature whose tentacles have the given fields."""
    return {"tentacles": fields}


BAD_SCENES: list[tuple[str, object, str]] = [
    ("version missing", {}, "version: is required"),
    ("version 2", {"version": 2}, "version: must be 1, got 2"),
    ("version as text", {"version": "1"}, 'version: must be 1, got "1"'),
    (
        "unknown top-level key",
        scene(colour="red"),
        f"colour: unknown key (allowed: {TOP_KEYS})",
    ),
    (
        "unknown creature key",
        scene({"legs": 8}),
        f"creatures[0].legs: unknown key (allowed: {CREATURE_KEYS})",
    ),
    (
        "unknown tentacles key",
        scene(tentacles(lenght=2)),
        f"creatures[0].tentacles.lenght: unknown key (allowed: {TENTACLE_KEYS})",
    ),
    (
        "unknown override key",
        scene(tentacles(overrides=[{"index": 0, "colour": "red"}])),
        "creatures[0].tentacles.overrides[0].colour: unknown key (allowed: damping, end_scale, "
        "index, link_length, link_radius, links, speed, strength, target_angle_deg, "
        "wave_amplitude_deg, wave_frequency, wavelength, writhe)",
    ),
    (
        "end_scale 1.7",
        scene({}, tentacles(end_scale=1.7)),
        "creatures[1].tentacles.end_scale: must be in (0, 1], got 1.7",
    ),
    (
        "end_scale 0",
        scene(tentacles(end_scale=0)),
        "creatures[0].tentacles.end_scale: must be in (0, 1], got 0",
    ),
    (
        "links 0",
        scene(tentacles(links=0)),
        "creatures[0].tentacles.links: must be in [1, 64], got 0",
    ),
    (
        "count 0",
        scene(tentacles(count=0)),
        "creatures[0].tentacles.count: must be in [1, 16], got 0",
    ),
    (
        "negative link_length",
        scene(tentacles(link_length=-0.05)),
        "creatures[0].tentacles.link_length: must be in [1e-06, 10], got -0.05",
    ),
    (
        "link_radius as string",
        scene(tentacles(link_radius="abc")),
        'creatures[0].tentacles.link_radius: must be a number, got "abc"',
    ),
    (
        "twist as string",
        scene(tentacles(twist="yes")),
        'creatures[0].tentacles.twist: must be a boolean, got "yes"',
    ),
    (
        "position with 4 numbers",
        scene({"position": [1, 2, 3, 4]}),
        "creatures[0].position: must have 2 to 3 items, got 4",
    ),
    (
        "gravity with 2 items",
        scene(physics={"gravity": [0, -9.81]}),
        "physics.gravity: must have exactly 3 items, got 2",
    ),
    ("fps 0", scene(physics={"fps": 0}), "physics.fps: must be in [4, 1000], got 0"),
    ("fps true", scene(physics={"fps": True}), "physics.fps: must be a number, got true"),
    (
        "substeps 0.5",
        scene(physics={"substeps": 0.5}),
        "physics.substeps: must be an integer, got 0.5",
    ),
    ("physics a list", scene(physics=[1, 2]), "physics: must be an object, got [1, 2]"),
    ("seed -1", scene(seed=-1), "seed: must be >= 0, got -1"),
    (
        "heading 400",
        scene({"heading_deg": 400}),
        "creatures[0].heading_deg: must be in [-360, 360], got 400",
    ),
    (
        "override index out of range",
        scene({}, tentacles(overrides=[{"index": 1}, {"index": 9}])),
        "creatures[1].tentacles.overrides[1].index: must be < count (8), got 9",
    ),
    (
        "override index equal to a lowered count",
        scene(tentacles(count=4, overrides=[{"index": 4}])),
        "creatures[0].tentacles.overrides[0].index: must be < count (4), got 4",
    ),
    (
        "override index negative",
        scene(tentacles(overrides=[{"index": -1}])),
        "creatures[0].tentacles.overrides[0].index: must be >= 0, got -1",
    ),
    (
        "override without index",
        scene(tentacles(overrides=[{"links": 3}])),
        "creatures[0].tentacles.overrides[0].index: is required",
    ),
    (
        "duplicate override index",
        scene(tentacles(overrides=[{"index": 2}, {"index": 3}, {"index": 2, "links": 4}])),
        "creatures[0].tentacles.overrides[2].index: duplicate index 2 "
        "(also creatures[0].tentacles.overrides[0])",
    ),
    (
        "duplicate creature names",
        scene({"name": "octo"}, {"name": "squid"}, {"name": "octo"}),
        'creatures[2].name: duplicate name "octo" (also creatures[0])',
    ),
    (
        "explicit name clashes with a default name",
        scene({"name": "creature_1"}, {}),
        'creatures[1].name: duplicate name "creature_1" (also creatures[0])',
    ),
    (
        "goal radius 0",
        scene({"goals": [{"position": [1, 1], "radius": 0}]}),
        "creatures[0].goals[0].radius: must be in (0, 1000], got 0",
    ),
    (
        "goal without position",
        scene({"goals": [{"position": [1, 1]}, {"radius": 0.5}]}),
        "creatures[0].goals[1].position: is required",
    ),
    (
        'suckers "all"',
        scene(tentacles(suckers="all")),
        'creatures[0].tentacles.suckers: must be one of "tip", "every_link", got "all"',
    ),
    (
        "bad systems import path",
        scene(systems=["os.system('rm -rf /')"]),
        "systems[0]: must be an import path 'package.module:ClassName', "
        "got \"os.system('rm -rf /')\"",
    ),
    ("creatures not an array", scene(creatures={}), "creatures: must be an array, got {}"),
    (
        "name with a space",
        scene({"name": "my octo"}),
        "creatures[0].name: must be letters, digits and _, not starting with a digit, "
        'got "my octo"',
    ),
    (
        "name with a trailing newline",
        scene({"name": "octo\n"}),
        "creatures[0].name: must be letters, digits and _, not starting with a digit, "
        'got "octo\\n"',
    ),
    (
        "name starting with a digit",
        scene({"name": "8arms"}),
        'creatures[0].name: must be letters, digits and _, not starting with a digit, got "8arms"',
    ),
    ("top level a list", [1, 2], "scene: must be an object, got [1, 2]"),
    (
        "unknown fur key",
        scene({"fur": {"colour_by": 1}}),
        "creatures[0].fur.colour_by: unknown key (allowed: behaviours, children, colour, controls, "
        "direction_reach, dynamics, groom, guides, min_elevation_deg, piloerection, preset, "
        "twist_max_deg, width)",
    ),
    (
        "unknown fur preset",
        scene({"fur": {"preset": "dog"}}),
        'creatures[0].fur.preset: must be one of "none", "hedgehog", "cat", "bird", got "dog"',
    ),
    (
        "groom with 1 point",
        scene({"fur": {"groom": {"points": 1}}}),
        "creatures[0].fur.groom.points: must be in [2, 64], got 1",
    ),
    (
        "groom region belly",
        scene({"fur": {"groom": {"region": "belly"}}}),
        'creatures[0].fur.groom.region: must be one of "all", "top", "side", "back", "rear", '
        '"front", got "belly"',
    ),
    (
        "control lift 2",
        scene({"fur": {"controls": [{"name": "a", "lift": 2}]}}),
        "creatures[0].fur.controls[0].lift: must be in [0, 1], got 2",
    ),
    (
        "control without name",
        scene({"fur": {"controls": [{"lift": 1}]}}),
        "creatures[0].fur.controls[0].name: is required",
    ),
    (
        "no controls",
        scene({"fur": {"controls": []}}),
        "creatures[0].fur.controls: must have 1 to 64 items, got 0",
    ),
    (
        "duplicate control name",
        scene({"fur": {"controls": [{"name": "a"}, {"name": "a"}]}}),
        'creatures[0].fur.controls[1].name: control name "a" is taken by '
        "creatures[0].fur.controls[0]",
    ),
    (
        "control name taken by a mirror twin",
        scene({"fur": {"controls": [{"name": "L_a", "mirror": "x"}, {"name": "R_a"}]}}),
        'creatures[0].fur.controls[1].name: control name "R_a" is taken by the twin of '
        "creatures[0].fur.controls[0]",
    ),
    (
        "guide names an unknown control",
        scene({"fur": {"guides": [{"points": [[0, 0, 0.1], [0, 0, 0.2]], "control": "x"}]}}),
        'creatures[0].fur.guides[0].control: no control named "x" (controls: main)',
    ),
    (
        "guide control missing from the preset",
        scene(
            {
                "fur": {
                    "preset": "cat",
                    "guides": [{"points": [[0, 0, 0], [0, 0, 1]], "control": "main"}],
                }
            }
        ),
        'creatures[0].fur.guides[0].control: no control named "main" '
        "(controls: neck, back, tail, L_flank, R_flank)",
    ),
    (
        "guide whose first points coincide",
        scene({"fur": {"guides": [{"points": [[0, 0, 0.1], [0, 0, 0.1]]}]}}),
        "creatures[0].fur.guides[0].points: the first two points must differ",
    ),
    (
        "behaviour repeated",
        scene({"fur": {"behaviours": ["lift", "lift"]}}),
        'creatures[0].fur.behaviours: must not repeat an item, got ["lift", "lift"]',
    ),
    (
        "track keys out of order",
        scene(fur_track("lift", {"time": 1, "value": 0}, {"time": 0.5, "value": 1})),
        "creatures[0].fur.controls[0].tracks[0].keys[1].time: must be > 1 (the previous key's), "
        "got 0.5",
    ),
    (
        "position track with a number",
        scene(fur_track("position", {"time": 0, "value": 0.5})),
        "creatures[0].fur.controls[0].tracks[0].keys[0].value: must be [x, y, z] for position, "
        "got 0.5",
    ),
    (
        "lift track with a vector",
        scene(fur_track("lift", {"time": 0, "value": [1, 2, 3]})),
        "creatures[0].fur.controls[0].tracks[0].keys[0].value: must be a number in [0, 1] for "
        "lift, got [1, 2, 3]",
    ),
    (
        "unknown easing",
        scene(fur_track("lift", {"time": 0, "value": 1, "easing": "bounce"})),
        'creatures[0].fur.controls[0].tracks[0].keys[0].easing: must be one of "linear", '
        '"ease", "slow_out", "slow_in", "step", got "bounce"',
    ),
    (
        "emotion radius 0",
        scene({"emotion": {"radius": 0}}),
        "creatures[0].emotion.radius: must be in (0, 1000], got 0",
    ),
    ("threat without path", scene(threats=[{"name": "roach"}]), "threats[0].path: is required"),
    (
        "threat path keys at one time",
        scene(
            threats=[
                {"path": [{"time": 1, "position": [0, 0, 0]}, {"time": 1, "position": [1, 0, 0]}]}
            ]
        ),
        "threats[0].path[1].time: must be > 1 (the previous key's), got 1",
    ),
    (
        "duplicate threat names",
        scene(threats=[{"name": "r", "path": [{"time": 0, "position": [0, 0, 0]}]}] * 2),
        'threats[1].name: duplicate name "r" (also threats[0])',
    ),
    (
        "threat position with 2 numbers",
        scene(threats=[{"path": [{"time": 0, "position": [0, 0]}]}]),
        "threats[0].path[0].position: must have exactly 3 items, got 2",
    ),
    (
        "threat mark as text",
        scene({"threat": "yes"}),
        'creatures[0].threat: must be a boolean, got "yes"',
    ),
    ("top level null", None, "scene: must be an object, got null"),
]
