"""Creature palettes: natural (muted skin tones, one per species, a little per creature)
and debug (a bright colour per creature), chosen in one function for sandbox and exports."""

from __future__ import annotations

import colorsys
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.skin.colours import (
    Look,
    creature_colour,
    creature_colours,
    look_in_take,
    look_in_world,
)
from ecs_tentacles.world import World
from tests.export.conftest import record

OCTOPUS = (8, *[6] * 8, 150)
SQUID = (10, *[9] * 10, 120)
MIXED = {
    "version": 1,
    "creatures": [
        {"name": "a", "position": [0, 0]},
        {"name": "b", "position": [3, 0]},
        {
            "name": "c",
            "position": [0, 3],
            "mantle": {"radius": 0.09},
            "tentacles": {"count": 5, "links": 4},
        },
    ],
}


def _hsv(rgb: np.ndarray) -> tuple[float, float, float]:
    return colorsys.rgb_to_hsv(*(float(v) for v in rgb))


def test_natural_colours_are_muted_skin_tones_a_species_apiece() -> None:
    crowd = [creature_colour(Look(f"o{k}", k, OCTOPUS)) for k in range(12)]
    for colour in crowd:
        hue, saturation, value = _hsv(colour)
        assert hue < 0.11 or hue > 0.94  # reds, pinks, corals, tans: no greens or blues
        assert 0.2 < saturation < 0.62 and 0.55 < value < 0.9  # muted, neither dark nor glaring
    spread = max(float(np.abs(a - b).max()) for a in crowd for b in crowd)
    assert 0.0 < spread < 0.12  # one species: a family of near tones, not one flat colour
    other = creature_colour(Look("o0", 0, SQUID))
    assert np.abs(other - crowd[0]).max() > 0.04  # another species, another tone
    assert_allclose(creature_colour(Look("o3", 3, OCTOPUS)), crowd[3])  # the same every time


def test_debug_is_the_bright_colour_per_creature() -> None:
    for k in range(6):
        assert_allclose(creature_colour(Look("x", k, OCTOPUS), "debug"), creature_colours(6)[k])
    with pytest.raises(ValueError, match="palette must be one of natural, debug"):
        creature_colour(Look("x", 0, OCTOPUS), "neon")


def test_a_take_and_its_world_give_the_same_looks() -> None:
    world, system = record(MIXED, 2)
    try:
        take = system.take()
        for k, name in enumerate(("a", "b", "c")):
            in_world = look_in_world(world, world.creature(name), k)
            assert look_in_take(take.header, k) == in_world
        assert (
            look_in_world(world, world.creature("a"), 0).body
            != look_in_world(world, world.creature("c"), 2).body
        )
    finally:
        world.close()


def test_the_sandbox_draws_the_palette_chosen(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox(MIXED, hud=False)
    renderer = sandbox.renderer
    world: World = sandbox.world
    entities = renderer.creature_entities
    for palette in ("natural", "debug", "natural"):
        renderer.set_palette(palette)
        sandbox.render()
        for k, entity in enumerate(entities):
            expected = creature_colour(look_in_world(world, entity, k), palette)
            assert_allclose(renderer.creature_colour[entity], expected)
            assert_allclose(renderer.mantle_instances[k, 11:14], expected, atol=1e-6)


def test_play_palette_option(capsys: pytest.CaptureFixture[str]) -> None:
    try:
        code = main(["play", "octopus", "--headless", "--json", "--palette", "neon"])
    except SystemExit as exit_:
        code = int(exit_.code or 0)
    assert code == 2
    assert "argument --palette: invalid choice: 'neon'" in capsys.readouterr().err


def test_a_scene_chooses_its_palette_and_play_palette_wins(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    scene = {**MIXED, "render": {"palette": "debug"}}
    sandbox = make_sandbox(scene, hud=False)
    renderer = sandbox.renderer
    entity = renderer.creature_entities[0]
    sandbox.render()
    assert renderer.palette == "debug"
    assert_allclose(
        renderer.creature_colour[entity],
        creature_colour(look_in_world(sandbox.world, entity, 0), "debug"),
    )
    shots = {}
    for name, data, option in (
        ("debug scene", scene, []),
        ("debug scene, --palette natural", scene, ["--palette", "natural"]),
        ("no palette in the scene", MIXED, []),
    ):
        path = tmp_path / f"{len(shots)}.json"
        path.write_text(json.dumps(data))
        shot = tmp_path / f"{len(shots)}.png"
        argv = ["play", str(path), "--headless", "--frames", "1", "--quiet", "--no-hud"]
        assert (
            main([*argv, *option, "--width", "320", "--height", "180", "--screenshot", str(shot)])
            == 0
        )
        with Image.open(shot) as image:
            shots[name] = np.asarray(image).astype(int)
    assert np.array_equal(shots["debug scene, --palette natural"], shots["no palette in the scene"])
    assert np.abs(shots["debug scene"] - shots["no palette in the scene"]).max() > 60


def test_a_bad_palette_in_a_scene_is_one_line_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "neon.json"
    path.write_text(json.dumps({**MIXED, "render": {"palette": "neon"}}))
    assert main(["play", str(path), "--headless", "--json"]) == 2
    err = capsys.readouterr().err
    assert err == f'error: {path}: render.palette: must be one of "natural", "debug", got "neon"\n'
