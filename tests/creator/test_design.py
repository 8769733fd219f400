"""The creature creator: its model, its command-line form, and what a scene builds from it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.components import Creature, Link, Tentacle
from ecs_tentacles.creator import CreatureDesign, DesignError, TentacleDesign
from ecs_tentacles.scene.load import bundled_scene, load_scene
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION


def interactive_squid() -> CreatureDesign:
    """What a user does in the creator window, step by step."""
    design = CreatureDesign()
    design.name = "squid"
    design.build(mantle_radius=0.12, mantle_height=0.3, count=6, links=10, end_scale=0.4)
    design.select(2)
    design.add_link()
    design.add_link()
    design.set_tentacle(link_length=0.09)
    design.select(4)
    design.set_tentacle(link_radius=0.03, end_scale=0.5)
    design.remove_link()
    return design


SQUID_ARGS = [
    "create",
    "--name",
    "squid",
    "--mantle-radius",
    "0.12",
    "--mantle-height",
    "0.3",
    "--tentacles",
    "6",
    "--links",
    "10",
    "--end-scale",
    "0.4",
    "--tentacle",
    "2:links=12,link_length=0.09",
    "--tentacle",
    "4:link_radius=0.03,end_scale=0.5,links=9",
]


def test_the_command_line_export_equals_the_interactive_model(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "squid.json"
    assert main([*SQUID_ARGS, "--out", str(out)]) == 0
    assert capsys.readouterr().out == f"{out}: creature 'squid': 6 tentacles, 61 links\n"
    exported = json.loads(out.read_text())
    assert exported == interactive_squid().scene()
    assert exported["creatures"][0]["tentacles"] == {
        "count": 6,
        "links": 10,
        "link_length": 0.07,
        "link_radius": 0.025,
        "end_scale": 0.4,
        "overrides": [
            {"index": 2, "links": 12, "link_length": 0.09},
            {"index": 4, "links": 9, "link_radius": 0.03, "end_scale": 0.5},
        ],
    }
    assert main(["validate", str(out)]) == 0
    load_scene(out)  # schema-valid


def _creature_numbers(world: World) -> list[tuple[str, int, int, float, float]]:
    rows = []
    for _, creature in world.query(Creature):
        for tentacle_entity in creature.tentacles:
            tentacle = world.component(tentacle_entity, Tentacle)
            for e in tentacle.links:
                link = world.component(e, Link)
                rows.append((creature.name, tentacle.index, link.index, link.length, link.radius))
    return rows


def test_loading_the_export_builds_exactly_the_creature_shown(tmp_path: Path) -> None:
    design = interactive_squid()
    shown = design.preview_world()
    design.export(tmp_path / "squid.json")
    loaded = World.from_scene(tmp_path / "squid.json", plugins=NO_LOCOMOTION)
    assert _creature_numbers(shown) == _creature_numbers(loaded)
    assert len(_creature_numbers(shown)) == 61
    np.testing.assert_array_equal(shown.transforms.pos, loaded.transforms.pos)
    np.testing.assert_array_equal(shown.transforms.quat, loaded.transforms.quat)
    m1, m2 = shown.physics.views[0].model, loaded.physics.views[0].model
    assert (m1.nbody, m1.njnt, m1.nu, m1.neq) == (m2.nbody, m2.njnt, m2.nu, m2.neq)
    np.testing.assert_array_equal(m1.geom_size, m2.geom_size)
    lengths = [link.length for link in (shown.component(e, Link) for e in _links(shown, 2))]
    np.testing.assert_allclose(lengths, 0.09 * (1 - np.arange(12) / 11 * 0.6))
    assert [s.lengths.size for s in design.shapes()] == [10, 10, 12, 10, 9, 10]
    shown.close()
    loaded.close()


def _links(world: World, k: int) -> list[int]:
    creature = next(c for _, c in world.query(Creature))
    return world.component(creature.tentacles[k], Tentacle).links


def test_build_resets_tentacles_and_keeps_unset_values() -> None:
    design = interactive_squid()
    design.build(count=4)
    assert design.tentacles == [TentacleDesign(10, 0.07, 0.025, 0.4)] * 4
    assert (design.mantle_radius, design.mantle_height, design.selected) == (0.12, 0.3, None)
    assert "overrides" not in design.creature_entry()["tentacles"]


def test_bad_values_name_the_field_and_change_nothing() -> None:
    design = interactive_squid()
    before = design.scene()
    cases = [
        (lambda: design.set_tentacle(2, links=65), "links: must be in [1, 64], got 65"),
        (lambda: design.set_tentacle(2, end_scale=0.0), "end_scale: must be in (0, 1], got 0.0"),
        (
            lambda: design.set_tentacle(2, link_length=-1),
            "link_length: must be in [1e-06, 10], got -1",
        ),
        (lambda: design.set_tentacle(2, links=2.5), "links: must be a whole number, got 2.5"),
        (lambda: design.select(6), "tentacle: must be in [0, 5], got 6"),
        (lambda: design.build(count=0), "count: must be in [1, 16], got 0"),
        (lambda: design.set_mantle(height=11), "mantle_height: must be in (0, 10], got 11"),
    ]
    for action, message in cases:
        with pytest.raises(DesignError) as caught:
            action()
        assert str(caught.value) == message
    assert design.scene() == before
    one = CreatureDesign(links=1)
    with pytest.raises(DesignError, match="links: must be in"):
        one.remove_link(0)
    with pytest.raises(DesignError, match="tentacle: no tentacle selected"):
        CreatureDesign().add_link()
    with pytest.raises(DesignError, match="name: must be letters"):
        CreatureDesign("9 lives")


def test_a_bundled_scene_round_trips_through_the_design() -> None:
    path = bundled_scene("asymmetric")
    design = CreatureDesign.from_scene(path)
    assert design.scene() == json.loads(path.read_text())
    assert design.tentacles[2] == TentacleDesign(4, 0.05, 0.035, 1.0)
    design.reset_tentacle(2)
    overrides = design.creature_entry()["tentacles"]["overrides"]
    assert [o["index"] for o in overrides] == [0, 3]  # tentacle 3 keeps its strength


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--end-scale", "1.5"], "error: argument --end-scale: must be in (0, 1], got 1.5"),
        (["--tentacle", "9:links=3"], "error: argument --tentacle: must be in [0, 7], got 9"),
        (["--name", "2fast"], "error: argument --name: must be letters, digits and _,"),
        (["--tentacles", "17"], "error: argument --tentacles: must be in [1, 16], got 17"),
    ],
)
def test_create_errors_exit_2_with_one_line(
    args: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["create", *args, "--out", str(tmp_path / "c.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1
    assert not (tmp_path / "c.json").exists()


def test_create_argument_errors(capsys: pytest.CaptureFixture[str]) -> None:
    for args, message in [
        (
            ["--tentacle", "two:links=3"],
            "must look like 2:links=12,end_scale=0.5, got 'two:links=3'",
        ),
        (["--tentacle", "1:colour=3"], "'colour=3': expected key=value with key one of links,"),
        (["--out", "scene.txt"], "argument --out: must end in .json, got 'scene.txt'"),
    ]:
        with pytest.raises(SystemExit):
            main(["create", *args])
        assert message in capsys.readouterr().err


def test_create_from_a_scene_edits_one_creature(tmp_path: Path) -> None:
    out = tmp_path / "odd.json"
    source = str(bundled_scene("asymmetric"))
    assert main(["create", "--from", source, "--tentacle", "1:links=9", "--out", str(out)]) == 0
    scene = json.loads(out.read_text())
    overrides = scene["creatures"][0]["tentacles"]["overrides"]
    assert {"index": 1, "links": 9} in overrides and len(overrides) == 4
    assert scene["seed"] == 5 and scene["name"] == "asymmetric"
    assert main(["create", "--from", source, "--creature", "nobody", "--out", str(out)]) == 2


def test_creator_sliders_come_from_the_schema_within_its_ranges() -> None:
    from ecs_tentacles.creator.limits import editor_setting
    from ecs_tentacles.scene.ranges import field_range
    from ecs_tentacles.scene.schema import core_schema

    tentacles = core_schema()["$defs"]["creature"]["properties"]["tentacles"]["properties"]
    assert tentacles["link_length"]["x-editor"]["label"] == "link length"  # in the schema file
    setting = editor_setting("link_length", "tentacles", "link_length", short=True)
    assert (setting.label, setting.low, setting.high) == ("length", 0.02, 0.2)
    count = editor_setting("count", "tentacles", "count")
    assert count.whole and count.high == field_range("tentacles", "count").high
