"""Controls: mirrored twins and nearest-control assignment, exactly."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.testing import assert_array_equal

from ecs_tentacles.fur import FurControl, FurGuide
from ecs_tentacles.fur.controls import expand_mirrors, mirror_name, nearest_control
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.world import World


def test_mirror_names() -> None:
    assert mirror_name("L_flank") == "R_flank"
    assert mirror_name("R_flank") == "L_flank"
    assert mirror_name("ear_L") == "ear_R"
    assert mirror_name("leftEar") == "rightEar"
    assert mirror_name("crest") == "crest_mirror"


def test_mirror_twins_get_mirrored_positions_and_position_keys() -> None:
    tracks = [
        {"attribute": "position", "keys": [{"time": 0, "value": [0.1, 0.2, 0.3]}]},
        {"attribute": "lift", "keys": [{"time": 0, "value": 0.5}]},
    ]
    controls = [
        {"name": "a", "position": [0.1, 0.2, 0.3], "mirror": "none", "tracks": []},
        {"name": "L_b", "position": [0.1, 0.2, 0.3], "mirror": "y", "tracks": tracks},
    ]
    out = expand_mirrors(controls)
    assert [c["name"] for c in out] == ["a", "L_b", "R_b"]
    assert out[2]["position"] == [0.1, -0.2, 0.3]
    assert out[2]["tracks"][0]["keys"][0]["value"] == [0.1, -0.2, 0.3]
    assert out[2]["tracks"][1] == tracks[1]
    assert controls[1]["tracks"][0]["keys"][0]["value"] == [0.1, 0.2, 0.3]  # not changed


def test_nearest_control_and_ties_go_to_the_first() -> None:
    roots = np.array([[0, 0, 0], [1, 0, 0], [0.5, 0, 0], [0, 2, 0.0]])
    controls = np.array([[0, 0, 0.1], [1, 0, 0.1], [0, 1.5, 0.0]])
    assert_array_equal(nearest_control(roots, controls), [0, 1, 0, 2])


def test_world_assigns_every_guide_to_its_nearest_control(make_world: Callable[..., World]) -> None:
    controls = [
        {"name": "L_side", "position": [0.0, 0.3, 0.0], "mirror": "y"},
        {"name": "front", "position": [0.3, 0.0, 0.1]},
    ]
    fur = {"groom": {"count": 300}, "controls": controls}
    world = make_world(
        {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}, "fur": fur}]}
    )
    made = {c.name: c for _, c in world.query(FurControl)}
    assert set(made) == {"L_side", "R_side", "front"}
    np.testing.assert_allclose(made["R_side"].position, [0.0, -0.3, 0.0])
    g = world.resource(FurData).guides
    rests = world.resource(FurData).controls.rest_position
    d = np.linalg.norm(g.root[:, None, :] - rests[None, :, :], axis=2)
    assert_array_equal(g.control_row, np.argmin(d, axis=1))
    assert set(g.control_row) == {0, 1, 2}


def test_a_listed_guide_can_name_its_control(make_world: Callable[..., World]) -> None:
    fur = {
        "groom": {"count": 0},
        "controls": [
            {"name": "near", "position": [0.2, 0, 0]},
            {"name": "far", "position": [-3, 0, 0]},
        ],
        "guides": [
            {"points": [[0.15, 0, 0], [0.2, 0, 0.01]]},
            {"points": [[0.15, 0, 0], [0.2, 0, 0.01]], "control": "far"},
        ],
    }
    world = make_world(
        {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}, "fur": fur}]}
    )
    guides = sorted((g.row, g.control_row) for _, g in world.query(FurGuide))
    assert guides == [(0, 0), (1, 1)]
