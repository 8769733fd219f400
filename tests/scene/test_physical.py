"""Load-time physical checks: the known blow-ups are refused with their JSON paths."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.components import Creature, Tentacle, Transform
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.scene.overlap import Bodies, find_overlaps
from ecs_tentacles.world import World

TOO_LIGHT = (
    "link 0 of tentacle {k} is too light to simulate (mass 2.2e-16 kg, inertia 1.1e-34 kg m^2;"
    " at least 1e-12 kg and 1e-12 kg m^2); raise link_radius, end_scale or density"
)
MOVE = "move it or set physics.separate_overlaps"


def scene(*creatures: dict[str, Any], **physics: Any) -> dict[str, Any]:
    return {"version": 1, "physics": physics, "creatures": list(creatures)}


REFUSED: list[tuple[str, dict[str, Any], str]] = [
    (
        "link radius 1e-9: MuJoCo's mass and inertia under mjMINVAL",
        scene({"tentacles": {"link_radius": 1e-9}}),
        "creatures[0].tentacles: " + TOO_LIGHT.format(k=0),
    ),
    (
        "the light link comes from an override",
        scene({"tentacles": {"overrides": [{"index": 1}, {"index": 2, "link_radius": 1e-9}]}}),
        "creatures[0].tentacles.overrides[1]: " + TOO_LIGHT.format(k=2),
    ),
    (
        "a tip link under 1 micrometre: MuJoCo's fromto points too close",
        scene({"tentacles": {"link_length": 1e-6, "end_scale": 0.1}}),
        "creatures[0].tentacles: link 1 of tentacle 0 is too short to simulate (9e-07 m;"
        " at least 1e-06 m); raise link_length or end_scale",
    ),
    (
        "a mantle 0.1 mm thin",
        scene({"mantle": {"radius": 0.0001}}),
        "creatures[0].mantle: too light to simulate (mass 2.5e-06 kg, inertia 1.3e-14 kg m^2;"
        " at least 1e-12 kg and 1e-12 kg m^2); raise radius, height or density",
    ),
    (
        "a mantle 1 nm high: MuJoCo's inertia triangle fails on rounding",
        scene({"mantle": {"height": 1e-9}}),
        "creatures[0].mantle: is too flat to simulate (height 1e-09 m, under 0.01 x its"
        " radius 0.15 m); raise height",
    ),
    (
        "one substep at 60 fps",
        scene({}, fps=60, substeps=1),
        "physics.substeps: a physics step of 1 / (fps * substeps) = 16.7 ms is longer than"
        " 2.5 ms, beyond which servos and contacts shake apart; at fps 60 use substeps >= 7",
    ),
    (
        "an undamped stiff servo",
        scene({"tentacles": {"strength": 100, "damping": 0}}),
        "creatures[0].tentacles.damping: 0 is below strength x physics step (100 x 2.08 ms ="
        " 0.208): a servo this stiff and this little damped shakes its links apart; raise"
        " damping to >= 0.208, lower strength or add substeps",
    ),
    (
        "an override's strength against the creature's damping",
        scene({"tentacles": {"overrides": [{"index": 0, "strength": 1000}]}}),
        "creatures[0].tentacles.overrides[0].damping: 0.5 is below strength x physics step"
        " (1000 x 2.08 ms = 2.08): a servo this stiff and this little damped shakes its links"
        " apart; raise damping to >= 2.08, lower strength or add substeps",
    ),
    (
        "gravity pulling sideways harder than friction holds",
        scene({}, gravity=[0, -30, -30]),
        "physics.gravity: pulls sideways (30 m/s^2) harder than ground_friction 0.4 holds"
        " against z = -30 (12 m/s^2): creatures would slide ever faster; tilt it less or raise"
        " ground_friction",
    ),
    (
        "gravity tilted past 45 degrees",
        scene({}, gravity=[0, -20, -10]),
        "physics.gravity: tilts more than 45 degrees (sideways 20 m/s^2 against z = -10):"
        " creatures would tumble over and fall ever faster; keep |sideways| <= |z|",
    ),
    (
        "gravity pointing up",
        scene({}, gravity=[0, 0, 5]),
        "physics.gravity: points up (z = 5): creatures would fall away from the ground; use z <= 0",
    ),
    (
        "needle links",
        scene({"tentacles": {"link_length": 10, "link_radius": 0.025}}),
        "creatures[0].tentacles: links 400 times longer than their radius (at most 100) are"
        " needles, not tentacle links; shorten link_length or thicken link_radius",
    ),
    (
        "a feather-light mantle on heavy tentacles",
        scene({"mantle": {"density": 0.01}}),
        "creatures[0].mantle: weighs 0.000141 kg against 6.04 kg of tentacles; keep the ratio"
        " within 10000 either way (change the mantle's or the tentacles' size or density)",
    ),
    (
        "link radius 10 m on a 15 cm mantle (issue 10's arcsin case)",
        scene({"tentacles": {"link_radius": 10}}),
        "creatures[0].mantle: weighs 5.65 kg against 1.25e+08 kg of tentacles; keep the ratio"
        " within 10000 either way (change the mantle's or the tentacles' size or density)",
    ),
    (
        "a creature started inside the ground",
        scene({"position": [0, 0, -0.1]}),
        "creatures[0].position: the creature starts 125 mm inside the ground; give z >= 0.025"
        " (its thickest link radius) or leave z out",
    ),
    (
        "two octopuses 1 m apart: their facing tentacles interpenetrate",
        scene({"position": [0, 0]}, {"position": [1, 0]}),
        f"creatures[1]: overlaps creatures[0] (tentacles interpenetrate by 29 mm at build); {MOVE}",
    ),
    (
        "a mantle standing on another creature's tentacle",
        scene({"position": [0, 0]}, {"position": [0.2, 0.1]}),
        "creatures[1]: overlaps creatures[0] (a tentacle and a mantle interpenetrate by 104 mm"
        f" at build); {MOVE}",
    ),
    (
        "mantles alone overlapping: one-tentacled creatures back to back",
        scene(
            {"position": [0, 0], "tentacles": {"count": 1}},
            {"position": [0, 0.2], "heading_deg": 180, "tentacles": {"count": 1}},
        ),
        f"creatures[1]: overlaps creatures[0] (mantles interpenetrate by 100 mm at build); {MOVE}",
    ),
]


@pytest.mark.parametrize(
    ("data", "expected"), [pytest.param(d, e, id=name) for name, d, e in REFUSED]
)
def test_known_blow_ups_are_refused_with_their_json_path(
    data: dict[str, Any], expected: str
) -> None:
    with pytest.raises(SceneError) as refused:
        load_scene(data)
    assert refused.value.problems == [expected]


@pytest.mark.parametrize(
    ("data", "expected"), [pytest.param(d, e, id=name) for name, d, e in REFUSED]
)
def test_the_cli_refuses_them_with_exit_2(
    data: dict[str, Any], expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    assert main(["validate", str(path)]) == 2
    assert capsys.readouterr().err == f"error: {path}: {expected}\n"


@pytest.fixture
def mujoco_warnings() -> Iterator[list[str]]:
    seen: list[str] = []
    mujoco.set_mju_user_warning(seen.append)
    yield seen
    mujoco.set_mju_user_warning(None)


@pytest.mark.parametrize(
    "tentacles",
    [
        pytest.param({"links": 2, "link_length": 0.01}, id="2 links of 1 cm"),
        pytest.param({"links": 2, "link_length": 0.01, "link_radius": 0.2}, id="fat 20 cm links"),
    ],
)
def test_a_stub_tentacle_hangs_straight_down_and_freezes_nobody(
    tentacles: dict[str, Any], mujoco_warnings: list[str]
) -> None:
    # the tip cannot reach the ground even hanging straight down: arcsin of > 1 before
    data = scene(
        {"name": "stub", "position": [0, 0], "tentacles": {"count": 2, **tentacles}},
        {"name": "octo", "position": [30, 0], "goals": [{"position": [32, 0]}]},
    )
    world = World.from_scene(data)
    stub = world.tentacles.creature_row == 0
    np.testing.assert_array_equal(world.tentacles.rest_pitch[stub], [np.pi / 2] * 2)
    octo = world.component(world.creature("octo"), Creature).tentacles
    tips = [world.component(world.component(t, Tentacle).links[-1], Transform) for t in octo]
    before = np.array([tip.pos for tip in tips])
    world.step(30)
    assert np.isfinite(world.motors.target).all()
    moved = np.linalg.norm(np.array([tip.pos for tip in tips]) - before, axis=1)
    assert moved.max() > 0.02  # the octopus's servos are driven, not zeroed by MuJoCo
    assert mujoco_warnings == []


def test_separate_overlaps_moves_later_creatures_until_none_overlap(
    mujoco_warnings: list[str],
) -> None:
    data = scene(
        {"position": [0, 0]},
        {"position": [0.2, 0.1]},
        {"position": [0.1, -0.1, 0.3]},
        separate_overlaps=True,
    )
    loaded = load_scene(data)
    positions = [c["position"] for c in loaded["creatures"]]
    assert positions[0] == [0, 0]
    assert len(positions[1]) == 2 and len(positions[2]) == 3  # z stays as given
    assert positions[2][2] == pytest.approx(0.3)
    bodies = [Bodies(*creature_layout(c).capsules()) for c in loaded["creatures"]]
    assert find_overlaps(bodies) == []
    assert data["creatures"][1]["position"] == [0.2, 0.1]  # the caller's dict is untouched
    world = World.from_scene(data)
    world.step(60)
    assert np.isfinite(world.transforms.pos).all()
    assert mujoco_warnings == []


def test_every_bundled_scene_still_loads() -> None:
    from ecs_tentacles.scene.load import bundled_scene, bundled_scene_names

    names = bundled_scene_names()
    assert len(names) >= 6
    for name in names:
        load_scene(bundled_scene(name))


def test_a_body_plan_checked_once_is_refused_at_every_creature_that_has_it() -> None:
    """Body plans are checked once per plan: each creature still gets its own lines."""
    light = {"tentacles": {"link_radius": 1e-4, "link_length": 0.01}}
    data = scene(
        {"position": [0, 0], **light},
        {"position": [3, 0]},
        {"position": [6, 0], "name": "third", **light},
    )
    with pytest.raises(SceneError) as refused:
        load_scene(data)
    assert [line.split(":")[0] for line in refused.value.problems] == [
        "creatures[0].tentacles",
        "creatures[2].tentacles",
    ]
    first, third = (line.split(":", 1)[1] for line in refused.value.problems)
    assert first == third
