"""Creatures in different physics groups push each other and never pass through."""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION
from tests.physics.clearance import bounding_sphere, clearance, creature_shapes

TOLERANCE = 0.005  # metres of interpenetration allowed, measured on the geoms


def _worst_clearance(world: World, frames: int, every: int = 3) -> float:
    """Step `frames`; the smallest gap between any two nearby creatures, checked often.
    Each creature's shapes are gathered once a checked frame, and a pair whose bounding
    spheres are farther apart than the smallest gap found so far is not measured (it
    cannot be smaller): the same answer as measuring every pair, in a third of the time."""
    entities = [int(e) for e in world.creatures.entity]
    mantles = world.creatures.mantle_row
    worst = np.inf
    for frame in range(frames):
        world.step(1)
        if frame % every:
            continue
        pos = world.transforms.pos[mantles, :2]
        near = np.linalg.norm(pos[:, None] - pos[None], axis=2) < 2.5
        pairs = [(i, j) for i, j in itertools.combinations(range(len(entities)), 2) if near[i, j]]
        shapes = {k: creature_shapes(world, entities[k]) for k in {k for p in pairs for k in p}}
        spheres = {k: bounding_sphere(s) for k, s in shapes.items()}
        for i, j in pairs:
            (ci, ri), (cj, rj) = spheres[i], spheres[j]
            if float(np.linalg.norm(ci - cj)) - ri - rj < worst:
                worst = min(worst, clearance(shapes[i], shapes[j]))
    return worst


def test_proxies_stand_where_the_other_creatures_bodies_are(
    make_world: Callable[..., World],
) -> None:
    scene = {
        "version": 1,
        "creatures": [
            {"name": "a", "position": [0.0, 0.0], "tentacles": {"count": 3, "links": 4}},
            {
                "name": "b",
                "position": [0.7, 0.0],
                "heading_deg": 180,  # tentacle tips 3 cm apart
                "tentacles": {"count": 3, "links": 4},
            },
            {"name": "far", "position": [9.0, 0.0], "tentacles": {"count": 3, "links": 4}},
        ],
    }
    world = make_world(scene, plugins=NO_LOCOMOTION)
    world.physics.proxies.update(world.transforms)  # as each frame starts
    a, b, far = world.physics.views
    assert far.proxies_used == 0 and a.proxies_used > 0 and b.proxies_used > 0
    # every proxy of a stands exactly on one of b's bodies, with its size
    used = a.proxy_mocap[: a.proxies_used]  # capsules first; no mantle is near
    placed = a.data.mocap_pos[used]
    bodies = world.transforms.pos[b.body_rows]
    nearest = np.linalg.norm(placed[:, None] - bodies[None], axis=2).min(axis=1)
    assert_allclose(nearest, 0.0, atol=1e-12)
    parked = np.setdiff1d(a.proxy_mocap, used)
    assert (a.data.mocap_pos[parked, 2] < -1000).all()  # the rest wait out of reach


HILLS = {"heightfield": {"size": [8, 4], "resolution": 41, "height": 0.3, "noise": {"seed": 7}}}


REDUCED_ONLY = {"lod": {"full": 0, "reduced": 8}}  # no hero: both run at the reduced tier


@pytest.mark.parametrize(
    ("terrain", "physics"),
    [({}, {}), (HILLS, {}), ({}, REDUCED_ONLY), (HILLS, REDUCED_ONLY)],
    ids=["plane", "rough ground", "plane, reduced", "rough ground, reduced"],
)
def test_two_creatures_driven_head_on_never_interpenetrate(
    make_world: Callable[..., World], terrain: dict[str, Any], physics: dict[str, Any]
) -> None:
    """Full or reduced (one step a frame, contact proxies as stiff as that step allows and
    pushing from farther away). Crowd avoidance off: it would steer them apart, and the
    contacts would never be tested (with the proxies parked they go ~11 cm into each
    other; reduced ones 25-31 mm with the full tier's proxy margin)."""
    scene = {
        "version": 1,
        "terrain": terrain,
        "physics": physics,
        "avoidance": {"enabled": False},
        "creatures": [
            {"name": "a", "position": [-1.2, 0.0], "goals": [{"position": [2.4, 0.0]}]},
            {
                "name": "b",
                "position": [1.2, 0.0],
                "heading_deg": 180,
                "goals": [{"position": [-2.4, 0.0]}],
            },
        ],
    }
    world = make_world(scene)
    worst = _worst_clearance(world, 12 * 60)
    tier = "reduced" if physics else "full"
    assert world.lod.counts()[tier] == 2
    assert worst > -TOLERANCE
    assert world.physics.health.recoveries == 0  # the physics never became unstable
    mantles = world.transforms.pos[world.creatures.mantle_row]
    assert mantles[0, 0] < mantles[1, 0]  # neither passed through the other


def _crossing_crowd(side: int) -> dict[str, Any]:
    """side x side small creatures on a grid, each heading for its mirror image."""
    tentacles = {"count": 3, "links": 5}
    creature: dict[str, Any] = {"name": "x", "position": [0, 0], "tentacles": tentacles}
    spacing = 2.0 * creature_reach(load_scene({"version": 1, "creatures": [creature]})[
        "creatures"][0]) + 0.2  # fmt: skip
    creatures = []
    for k, (i, j) in enumerate(itertools.product(range(side), repeat=2)):
        x, y = (i - (side - 1) / 2) * spacing, (j - (side - 1) / 2) * spacing
        creatures.append(
            {
                "name": f"c{k}",
                "position": [x, y],
                "heading_deg": float(np.degrees(np.arctan2(-y, -x))),
                "tentacles": tentacles,
                "goals": [{"position": [-x, -y]}],
            }
        )
    return {"version": 1, "creatures": creatures}


def test_sixteen_creatures_with_crossing_goals_stay_apart_for_20_seconds(
    make_world: Callable[..., World],
) -> None:
    """All reduced (16 fit the reduced budget), crowd avoidance off so that they press into
    each other and the contacts are what keeps them apart (with avoidance on they hardly
    touch): a creature squeezed between neighbours steps twice a frame (`NEAR_SPLIT`)."""
    scene = _crossing_crowd(4)
    scene["avoidance"] = {"enabled": False}
    world = make_world(scene)
    start = world.transforms.pos[world.creatures.mantle_row].copy()
    worst = _worst_clearance(world, 20 * 60, every=9)
    assert world.lod.counts()["reduced"] == 16
    assert worst > -TOLERANCE
    assert world.physics.health.recoveries == 0
    end = world.transforms.pos[world.creatures.mantle_row]
    assert np.median(np.linalg.norm(end[:, :2] - start[:, :2], axis=1)) > 0.3  # they crawled


def test_the_sense_kernel_gives_the_numpy_numbers_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import proxies as module

    world = make_world(crowd_scene(12, seed=3))  # 8 body plans: bodies per creature vary
    world.step(20)
    assert module.KERNELS.get() is not None  # numba comes with the dev extra
    sensed = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        sensed.append(world.physics.proxies.sense(world.transforms))
    for parallel_from in (1 << 40, 0):  # a frame's spheres, on one core and on all
        monkeypatch.setattr(module, "PARALLEL_REACH", parallel_from)
        monkeypatch.setattr(module.KERNELS, "backend", "auto")
        _, _, centre, radius = world.physics.proxies.sense(world.transforms, 1000 + parallel_from)
        np.testing.assert_array_equal(centre, sensed[1][2])
        np.testing.assert_array_equal(radius, sensed[1][3])
    for kernel, numpy_path in zip(*sensed, strict=True):
        np.testing.assert_array_equal(kernel, numpy_path)


def test_a_frame_that_gathers_only_the_near_creatures_bodies_moves_as_one_that_copies_all(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """With numba a frame's `sense` copies the bodies of the creatures near another only
    (`ContactProxies.gather`); the numpy path copies every body: the same motion."""
    from ecs_tentacles.physics import proxies as module

    small = {"count": 3, "links": 4}
    creatures = [
        {"name": "a", "position": [0.0, 0.0], "tentacles": small},
        {"name": "b", "position": [0.7, 0.0], "heading_deg": 180, "tentacles": small},
    ]  # tentacle tips 3 cm apart: proxies from the first frame
    creatures += [{"name": f"far{k}", "position": [9.0 + 3 * k, 0.0]} for k in range(7)]
    scene = {"version": 1, "creatures": creatures}  # 9: past the full budget, lod decides
    runs = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        world = make_world(scene)
        touching, gathered = 0, []
        for _ in range(30):
            world.step(1)
            touching += world.physics.proxies.in_use
            lazy = world.physics.proxies._lazy
            gathered.append(-1 if lazy is None else int(lazy.gathered.sum()))
        runs.append((world.transforms.pos.copy(), world.transforms.quat.copy(), touching))
        if backend == "auto":
            assert touching == 30  # proxies placed every frame: a's and b's bodies gathered
            assert max(gathered) == 2  # theirs, and no one else's
    for lazy_run, eager_run in zip(*runs, strict=True):
        np.testing.assert_array_equal(lazy_run, eager_run)


def test_the_pair_gaps_kernel_gives_the_numpy_numbers_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import proxies as module

    world = make_world(crowd_scene(12, seed=3, spacing=1.6))  # packed: spheres overlap
    world.step(20)
    proxies = world.physics.proxies
    pos, _, centre, radius = proxies.sense(world.transforms)
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        found.append(proxies.pair_gaps(pos, centre, radius, 0.5))
    for kernel, numpy_path in zip(*found, strict=True):
        np.testing.assert_array_equal(kernel, numpy_path)
    gaps = found[0][2]
    assert np.isfinite(gaps).sum() >= 3 and np.isinf(gaps).sum() >= 1  # near and not quite


def test_the_proxy_candidates_kernel_gives_the_numpy_numbers_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Which bodies stand in as proxies, for whom and in which slot: the same with numba
    and without, in a packed crowd where creatures have more candidates than a pool holds
    (ranked by their nearest own body)."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import proxies as module

    world = make_world(crowd_scene(12, seed=3, spacing=1.6))  # packed: spheres overlap
    world.step(20)
    monkeypatch.setattr(module, "MARGIN", 0.5)  # as if the neighbours were 0.45 m nearer
    proxies = world.physics.proxies
    pos, _, centre, radius = proxies.sense(world.transforms)
    a, b = proxies._pairs(centre, radius, module.MARGIN)
    assert module.KERNELS.get() is not None
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        found.append(proxies._assign(a, b, pos, centre, radius))
    for kernel, numpy_path in zip(*found, strict=True):
        np.testing.assert_array_equal(kernel, numpy_path)
    who = proxies._candidates(a, b, pos, centre, radius)[0]
    crowded = np.bincount(who) > module.POOL.min()
    assert crowded.sum() >= 2 and (~crowded[who]).any()  # both rankings were compared
    assert len(found[0][0]) >= 20 and len(np.unique(found[0][0])) >= 4


def test_the_refresh_kernel_gives_the_numpy_numbers_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Between a frame's rounds the near creatures' bodies come from their last step and
    their reach spheres are made again: the same numbers with numba and without."""
    from ecs_tentacles.physics import proxies as module

    small = {"count": 3, "links": 4}
    creatures = [
        {"name": "a", "position": [0.0, 0.0], "tentacles": small},
        {"name": "b", "position": [0.7, 0.0], "heading_deg": 180, "tentacles": small},
        {"name": "far", "position": [6.0, 0.0]},
    ]  # a and b: tentacle tips 3 cm apart, proxies from the first frame
    world = make_world({"version": 1, "creatures": creatures})
    world.step(5)
    proxies = world.physics.proxies
    assert proxies.in_use
    for batch in world.physics.batches:  # as if the near creatures had stepped on
        batch.xpos += 0.01 * (1 + np.arange(batch.xpos.shape[1]))[None, :, None]
    used = world.physics.proxies_used.copy()
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        world.physics.proxies_used[:] = used
        proxies._sensed = proxies._lazy = None
        proxies._within = tuple(a.copy() for a in proxies.sense(world.transforms))
        proxies.refresh(world.transforms)
        found.append(proxies._within)
    for kernel, numpy_path in zip(*found, strict=True):
        np.testing.assert_array_equal(kernel, numpy_path)
    pos, _, centre, radius = found[0]
    before = proxies.sense(world.transforms)
    moved = np.flatnonzero(used > 0)
    assert len(moved) == 2 and not (pos == before[0]).all()  # a and b moved, far did not
    assert (radius[moved] != before[3][moved]).all() and radius[2] == before[3][2]
    assert (centre[moved] != before[2][moved]).all()


def test_a_replayed_creature_gets_no_proxies_and_the_crowd_moves_as_when_it_did(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A KINEMATIC creature is not stepped: proxies placed for it were work for nothing.
    It gets none now (its neighbours still get proxies of its bodies), and every pose
    is the same, bit for bit, as when it got them."""
    from ecs_tentacles.physics import proxies as module
    from ecs_tentacles.physics.tiers import KINEMATIC

    small = {"count": 4, "links": 5}
    creatures = [  # every other one turned 45 degrees: reach spheres overlap, tentacles not
        {
            "name": f"c{i}",
            "position": [0.85 * (i % 4), 0.85 * (i // 4)],
            "heading_deg": 45.0 * (i % 2),
            "tentacles": small,
            "goals": [{"position": [0.85 * (i % 4) + 1.0, 0.85 * (i // 4)]}],
        }
        for i in range(8)
    ]
    lod = {"full": 0, "reduced": 1, "hold_seconds": 0.1}
    scene = {"version": 1, "physics": {"lod": lod}, "creatures": creatures}
    runs = []
    for replayed_get_proxies in (True, False):
        with monkeypatch.context() as patch:
            if replayed_get_proxies:  # as before: no creature's tier is KINEMATIC to it
                patch.setattr(module, "KINEMATIC", -1)
            world = make_world(scene)
            poses, served = [], 0
            for _ in range(40):
                world.step(1)
                roster = world.physics.roster
                served += int(((roster.tier == KINEMATIC) & (roster.proxies_used > 0)).sum())
                poses.append(world.transforms.pos.copy())
            runs.append((np.array(poses), served, world.lod.counts()))
    (before, served_before, tiers), (after, served_after, _) = runs
    assert tiers["kinematic"] >= 2 and served_before >= 20  # replayed creatures had proxies
    assert served_after == 0
    np.testing.assert_array_equal(after, before)
