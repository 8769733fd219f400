"""Goal paths in the sandbox: a few creatures show every path; a crowd shows the
selected creature's path and faded rings, not a starburst of lines."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ecs_tentacles.locomotion.render import ALL_PATHS, path_lines
from ecs_tentacles.render.registries import RenderView
from ecs_tentacles.world import World


def _scene(count: int) -> dict:
    creatures = [
        {"name": f"c{i}", "position": [3.0 * i, 0], "goals": [{"position": [3.0 * i, 5.0]}]}
        for i in range(count)
    ]
    return {"version": 1, "creatures": creatures}


def _legs(world: World, selected: int | None) -> np.ndarray:
    """The moving legs (creature -> its goal) drawn this frame, as line-list vertices."""
    creatures = [world.creature(f"c{i}") for i in range(len(world.creatures))]
    view = RenderView(
        world.transforms.pos.copy(),
        world.transforms.quat.copy(),
        creatures,
        {c: np.array([0.8, 0.3, 0.2]) for c in creatures},
        selected=selected,
    )
    return path_lines(world, view)[1]


def test_a_few_creatures_show_every_path(make_world: Callable[..., World]) -> None:
    world = make_world(_scene(3))
    assert len(_legs(world, None)) == 2 * 3


def test_a_crowd_shows_only_the_selected_creatures_path(make_world: Callable[..., World]) -> None:
    count = ALL_PATHS + 4
    world = make_world(_scene(count), plugins={"fur": False})
    assert len(_legs(world, None)) == 0  # nothing selected: no starburst
    chosen = world.creature("c5")
    legs = _legs(world, chosen)
    assert len(legs) == 2  # one leg: from c5 to its goal
    np.testing.assert_allclose(legs[1, :2], [15.0, 5.0])
