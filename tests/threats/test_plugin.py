"""The threats plugin: markers for the sandbox, snapshots, and a world without it."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.render.registries import Marker, Spheres
from ecs_tentacles.threats.data import ThreatData
from ecs_tentacles.threats.plugin import THREAT_RGBA, THREAT_SIZE
from ecs_tentacles.world import World

TENTACLES = {"count": 3, "links": 2}
PATH = [
    {"time": 0, "position": [0.0, 2.0, 0.1], "easing": "linear"},
    {"time": 2, "position": [2.0, 2.0, 0.1]},
]
SCENE: dict[str, Any] = {
    "version": 1,
    "creatures": [{"tentacles": TENTACLES}],
    "threats": [{"name": "roach", "path": PATH}, {"name": "moth", "path": PATH[1:]}],
}


def _threat_spheres(world: World) -> list[Marker]:
    """The markers of the threats plugin's `Spheres` entries."""
    entries = [e for owner, e in world.registry(Spheres).items() if owner == "threats"]
    assert entries
    return [marker for spheres in entries for marker in spheres(world)]


def test_its_spheres_mark_every_path_threat(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    world.step(31)  # t = 0.5 s
    (marker,) = _threat_spheres(world)
    assert marker.size == THREAT_SIZE and marker.rgba == THREAT_RGBA
    where = np.array([[0.5, 2.0, 0.1], [2.0, 2.0, 0.1]])  # roach halfway, moth at its key
    assert_allclose(marker.positions, where + [0.0, 0.0, 0.04])  # drawn just above


def test_no_path_threat_no_marker(make_world: Callable[..., World]) -> None:
    marked = {"tentacles": TENTACLES, "threat": True}  # a threat creature draws as itself
    world = make_world({"version": 1, "creatures": [marked]})
    assert _threat_spheres(world) == []
    assert (
        world.resource(ThreatData).positions(world) == {} and len(world.resource(ThreatData)) == 1
    )


def test_restore_puts_threats_back_where_they_were(make_world: Callable[..., World]) -> None:
    world = make_world(SCENE)
    store = world.resource(ThreatData).store
    world.step(31)
    snap = world.snapshot()
    then = store.pos.copy()
    world.step(30)
    later = store.pos.copy()
    assert not np.array_equal(then, later)
    world.restore(snap)
    assert_array_equal(store.pos, then)
    world.step(30)
    assert_array_equal(store.pos, later)


def test_a_world_without_the_plugin_has_no_threats(make_world: Callable[..., World]) -> None:
    world = make_world(
        {"version": 1, "creatures": [{"tentacles": TENTACLES}]}, plugins={"threats": False}
    )
    assert world.get_resource(ThreatData) is None
    assert "threats" not in world.schedule.names and "threats" not in world.stores
