"""The REDUCED tier's cheaper model (`ecs_tentacles.physics.reduced`), seen as users see it:
the full skeleton drawn, no pop at tier moves, the same crawl."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.physics.batch import STATE
from ecs_tentacles.physics.tiers import FULL, REDUCED, reduced_substeps
from ecs_tentacles.terrain.presets import rocky
from ecs_tentacles.world import World

S = mujoco.mjtState


def _crowd(
    count: int, lod: dict[str, Any], terrain: bool = False, mantle: float | None = None
) -> dict[str, Any]:
    """`count` default creatures 3 m apart, each crawling 3 m along +x (mantle radius
    `mantle`, if given)."""
    creatures = []
    for i in range(count):
        x, y = 3.0 * (i % 4) - 4.0, 3.0 * (i // 4) - 2.0
        entry = {"name": f"c{i}", "position": [x, y], "goals": [{"position": [x + 3, y]}]}
        if mantle is not None:
            entry["mantle"] = {"radius": mantle}
        creatures.append(entry)
    scene: dict[str, Any] = {"version": 1, "physics": {"lod": lod}, "creatures": creatures}
    if terrain:
        scene["terrain"] = rocky(np.array([c["position"] for c in creatures]), 1.0, 0)
    return scene


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(points,) distance of each point to the nearest of the segments a[j] -> b[j]."""
    ab = b - a
    t = np.einsum("pjk,jk->pj", points[:, None, :] - a[None], ab) / np.sum(ab * ab, axis=1)
    nearest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def test_a_reduced_creature_draws_the_full_skeleton_on_its_chain(
    make_world: Callable[..., World],
) -> None:
    world = make_world(_crowd(2, {"full": 0, "reduced": 8, "hold_seconds": 0}))
    world.step(90)
    assert world.lod.counts()["reduced"] == 2
    batch = world.physics.batches[0]
    reduced = batch.reduced
    assert reduced is not None and reduced.model.nbody < batch.model.nbody - 30  # cheaper
    scratch = batch.scratch_for(0, REDUCED)
    m, d = scratch.model, scratch.data
    for row in range(len(batch)):
        shown = world.transforms.pos[batch.body_rows[row]]
        assert shown.shape == (len(batch.body_ids), 3) and np.isfinite(shown).all()
        mujoco.mj_setState(m, d, batch.rstate[batch.rslot[row]], STATE)
        mujoco.mj_kinematics(m, d)
        links = [i for i in range(1, m.nbody) if not m.body_mocapid[i] >= 0]
        axis = np.array([d.xmat[i].reshape(3, 3)[:, 0] for i in links])
        half = np.array([m.geom_size[m.body_geomadr[i], 1] for i in links])[:, None]
        centre = d.xpos[links]
        distance = _segment_distance(shown[1:], centre - half * axis, centre + half * axis)
        assert distance.max() <= 0.01, f"a link is {distance.max() * 1000:.1f} mm off the chain"


@pytest.mark.parametrize("terrain", [False, True], ids=["plane", "rocky"])
def test_tier_moves_do_not_pop(make_world: Callable[..., World], terrain: bool) -> None:
    """Demotion shows the fitted reduced chain: within 2 cm of the full pose; promotion
    starts the full model from exactly the reduced pose shown."""
    world = make_world(_crowd(4, {"full": 8, "reduced": 8}, terrain))
    batch = world.physics.batches[0]
    batch.prepare(REDUCED, 1)
    reduced = batch.reduced
    assert reduced is not None
    full = batch.scratch_for(0, FULL)
    worst = 0.0
    for _ in range(12):
        world.step(10)
        for row in range(len(batch)):
            fitted = np.zeros(reduced.size)
            reduced.fit_state(batch.state[row], fitted)
            shown = batch.state[row].copy()
            reduced.expand_state(fitted, shown)
            full.data.qpos[:] = shown[batch.slices[int(S.mjSTATE_QPOS)]]
            mujoco.mj_kinematics(full.model, full.data)
            jump = np.linalg.norm(full.data.xpos[batch.body_ids] - batch.xpos[row], axis=1)
            worst = max(worst, float(jump.max()))
    assert worst <= 0.02, f"a demotion moves a link {worst * 1000:.1f} mm"
    # promotion: the full state is the one the reduced creature was shown in
    world = make_world(_crowd(2, {"full": 0, "reduced": 8, "hold_seconds": 0}, terrain))
    world.step(30)
    batch = world.physics.batches[0]
    before = batch.state.copy()
    world.lod.promote(world.creature("c0"))
    world.lod.update(world)
    assert world.lod.tier_of(world.creature("c0")) == "full"
    np.testing.assert_array_equal(batch.state, before)


def test_a_reduced_creature_takes_one_step_a_frame_and_stands_as_high_as_its_full_self(
    make_world: Callable[..., World],
) -> None:
    """At the default 480 Hz a reduced creature takes one MuJoCo step a frame (60 Hz), its
    contacts as soft as that step allows: it still lands on the ground and stands on its
    tentacles within 3 mm of its full self's height (1.7 mm lower measured), never in it."""
    heights = {}
    for tier, lod in (("full", {"full": 8}), ("reduced", {"full": 0, "reduced": 8})):
        world = make_world(_crowd(4, lod))
        assert reduced_substeps(world.settings.substeps) == 1
        rows = world.creatures.mantle_row
        world.step(120)
        assert world.lod.counts()[tier] == 4
        assert world.physics.health.recoveries == 0
        heights[tier] = world.transforms.pos[rows, 2].copy()
    assert np.all(heights["reduced"] > 0.1), heights  # on its tentacles, not on its mantle
    np.testing.assert_allclose(heights["reduced"], heights["full"], atol=0.003)


def test_a_reduced_crowd_crawls_like_a_full_one(make_world: Callable[..., World]) -> None:
    progress = {}
    for tier, lod in (("full", {"full": 8}), ("reduced", {"full": 0, "reduced": 8})):
        world = make_world(_crowd(4, lod))
        rows = [world.component(world.creature(f"c{i}"), Transform).row for i in range(4)]
        start = world.transforms.pos[rows, 0].copy()
        world.step(300)
        assert world.lod.counts()[tier] == 4
        assert world.physics.health.recoveries == 0
        progress[tier] = float(np.mean(world.transforms.pos[rows, 0] - start))
    assert progress["full"] > 0.2
    assert abs(progress["reduced"] / progress["full"] - 1.0) < 0.25, progress


def test_a_heavy_mantle_slows_a_reduced_creature_no_more_than_a_full_one(
    make_world: Callable[..., World],
) -> None:
    """The reduced servos match their groups' stiffness at the tip, where a gripping
    stroke pulls: softer ones let a heavy creature's tentacles sag more than the full
    ones do, and it crawled slower than itself (servos in series at 0.8: 0.94 of full
    against 1.07 with a light mantle). At 60 Hz (one step a frame) the heavy ones keep
    a little less of their pace than at 120 Hz: 1.02 against 1.08 light (120 Hz: 1.08
    against 1.10)."""
    pace = {}
    for radius in (0.12, 0.19):
        progress = {}
        for tier, lod in (("full", {"full": 8}), ("reduced", {"full": 0, "reduced": 8})):
            world = make_world(_crowd(4, lod, mantle=radius))
            rows = [world.component(world.creature(f"c{i}"), Transform).row for i in range(4)]
            start = world.transforms.pos[rows, 0].copy()
            world.step(300)
            assert world.lod.counts()[tier] == 4
            progress[tier] = world.transforms.pos[rows, 0] - start
        ratio = progress["reduced"] / progress["full"]
        assert np.all(np.abs(ratio - 1.0) < 0.2), (radius, ratio)
        pace[radius] = float(ratio.mean())
    assert abs(pace[0.19] - pace[0.12]) < 0.07, pace


@pytest.mark.parametrize("damping", [2.1, 100.0], ids=["least-damping", "heavy-damping"])
def test_the_stiffest_servos_the_schema_allows_simulate_at_the_reduced_tier(
    make_world: Callable[..., World], damping: float
) -> None:
    """Strength 1000 (the schema's maximum) with the least damping the scene allows
    (strength x physics step) and with heavy damping: the 120 Hz reduced step blew these
    creatures up (4 to 6 recoveries in 3 s, frozen since), the full model never; a row
    this stiff takes shorter reduced steps. A default creature keeps the one step."""
    scene = _crowd(2, {"full": 0, "reduced": 8})
    for creature in scene["creatures"]:
        creature["tentacles"] = {"strength": 1000.0, "damping": damping}
    scene["creatures"].append({"name": "plain", "position": [0.0, 4.0]})
    world = make_world(scene)
    rows = [world.component(world.creature(f"c{i}"), Transform).row for i in range(2)]
    start = world.transforms.pos[rows, 0].copy()
    world.step(180)
    assert world.lod.counts()["reduced"] == 3
    assert world.physics.health.recoveries == 0
    assert np.all(world.transforms.pos[rows, 0] - start > 0.03)  # they crawl, not frozen
    splits = []
    for name in ("c0", "plain"):
        view = world.physics.view_of(world.component(world.creature(name), Creature))
        reduced, model = view.batch.reduced, view.batch.scratch_for(0, REDUCED).model
        assert reduced is not None
        batch, row = view.batch, view.row
        servos = reduced.servos(batch.kp[[row]], batch.kv[[row]], batch.torque[[row]])
        splits.append(reduced.write_overlay(batch, model, row, servos, 0))
    assert splits[0] > 1 and splits[1] == 1


def test_a_gain_past_any_schema_value_splits_the_step_within_bounds(
    make_world: Callable[..., World],
) -> None:
    """A script may set gains the schema never allows: a huge one takes at most
    MAX_SPLIT shorter steps, and one that is not finite no split at all (its blow-up is
    the health check's to see), never an exception in a stepping thread."""
    from ecs_tentacles.physics.reduced import MAX_SPLIT

    world = make_world(_crowd(1, {"full": 0, "reduced": 8}))
    world.step(2)
    batch = world.physics.batches[0]
    reduced, model = batch.reduced, batch.scratch_for(0, REDUCED).model
    assert reduced is not None
    splits = []
    for gain in (5.0, 1e9, np.nan, np.inf):  # 5 at every hinge, the tips' too: one step
        batch.kp[0] = gain
        with np.errstate(divide="ignore"):
            servos = reduced.servos(batch.kp[:1], batch.kv[:1], batch.torque[:1])
            splits.append(reduced.write_overlay(batch, model, 0, servos, 0))
    assert splits == [1, MAX_SPLIT, 1, 1]


def test_a_heavily_damped_reduced_creature_crawls_like_its_full_self(
    make_world: Callable[..., World],
) -> None:
    """Damping 5 (ten times the default): a servo this damped creeps to its target at
    kp / kv, and the reduced tier's extra damping (which calms the swing of a chain
    matched at the tip) once halved that pace: 0.58 of full."""
    progress = {}
    for tier, lod in (("full", {"full": 8}), ("reduced", {"full": 0, "reduced": 8})):
        scene = _crowd(2, lod)
        for creature in scene["creatures"]:
            creature["tentacles"] = {"damping": 5.0}
        world = make_world(scene)
        rows = [world.component(world.creature(f"c{i}"), Transform).row for i in range(2)]
        start = world.transforms.pos[rows, 0].copy()
        world.step(300)
        assert world.lod.counts()[tier] == 2
        progress[tier] = float(np.mean(world.transforms.pos[rows, 0] - start))
    assert progress["full"] > 0.2
    assert abs(progress["reduced"] / progress["full"] - 1.0) < 0.15, progress


def test_recovering_one_reduced_creature_leaves_the_others_alone(
    make_world: Callable[..., World],
) -> None:
    runs = []
    for broken in (False, True):
        world = make_world(_crowd(4, {"full": 0, "reduced": 8, "hold_seconds": 0}))
        world.step(20)
        if broken:
            batch = world.physics.batches[0]
            batch.state[1, batch.slices[int(S.mjSTATE_QVEL)]] = np.nan  # c1 blows up
        world.step(20)
        runs.append(world)
    assert runs[1].physics.health.recoveries >= 1
    for name in ("c0", "c2", "c3"):
        rows = runs[0].physics.views[int(name[1])].body_rows
        np.testing.assert_array_equal(runs[0].transforms.pos[rows], runs[1].transforms.pos[rows])
    assert np.isfinite(runs[1].transforms.pos).all()


def test_a_rows_reduced_servos_are_the_same_bits_whatever_rows_share_the_call(
    make_world: Callable[..., World],
) -> None:
    """A frame's reduced rows are shared among the threads as they free up, so a row's
    servos must not depend on which rows are computed with it (1 and 2 threads give the
    same take): all rows at once, each alone and a shuffled half give the same bits."""
    world = make_world(_crowd(6, {"full": 0, "reduced": 8}))
    world.step(3)
    batch = world.physics.batches[0]
    reduced = batch.reduced
    assert reduced is not None and len(batch) == 6
    rng = np.random.default_rng(0)
    factors = rng.uniform(0.5, 40.0, size=batch.kp.shape)  # every row different and stiff
    factors[0] = 1.0  # but the first: a default creature's servos
    batch.kp[:] *= factors
    rows = np.arange(len(batch))
    together = reduced.servos(batch.kp[rows], batch.kv[rows], batch.torque[rows])
    assert together.split.max() > 1 == together.split.min()
    some = rng.permutation(rows)[: len(rows) // 2]
    half = reduced.servos(batch.kp[some], batch.kv[some], batch.torque[some])
    for field in ("kp", "kv", "torque", "split"):
        np.testing.assert_array_equal(getattr(half, field), getattr(together, field)[some])
        for row in rows.tolist():
            alone = reduced.servos(batch.kp[[row]], batch.kv[[row]], batch.torque[[row]])
            np.testing.assert_array_equal(getattr(alone, field)[0], getattr(together, field)[row])
    # and they are the gains the module docstring describes: matched at the tip, x 0.9
    from ecs_tentacles.physics.reduced import STIFFNESS_GAIN

    inverse = 1.0 / batch.kp[0, reduced.full_u]
    np.testing.assert_allclose(together.kp[0], STIFFNESS_GAIN / (reduced.compliance @ inverse))


def test_a_shares_overlay_writer_writes_what_write_overlay_writes(
    make_world: Callable[..., World],
) -> None:
    """The reduced step writes each row's overlay with `overlay_writer` (lookups made once
    for a share): the same values in the same places of the scratch model as
    `write_overlay`, row after row, split steps, sucker anchors and proxies included."""
    import copy

    world = make_world(_crowd(6, {"full": 0, "reduced": 8}))
    world.step(3)
    batch = world.physics.batches[0]
    reduced = batch.reduced
    assert reduced is not None and len(batch) == 6
    rng = np.random.default_rng(1)
    batch.kp[:] *= rng.uniform(0.5, 40.0, size=batch.kp.shape)  # some rows' steps split
    batch.anchor[:] = rng.normal(size=batch.anchor.shape)
    batch.near[:] = [True, False, True, True, False, False]
    batch.proxy_size[:] = rng.uniform(0.01, 0.2, size=batch.proxy_size.shape)
    rows = np.array([4, 0, 5, 2, 3])
    servos = reduced.servos(batch.kp, batch.kv, batch.torque, rows)
    assert servos.split.max() > 1
    old, new = copy.copy(reduced.model), copy.copy(reduced.model)
    write = reduced.overlay_writer(batch, new, servos)
    fields = ("actuator_gainprm", "actuator_biasprm", "actuator_forcerange", "eq_data",
              "geom_size", "geom_rbound", "geom_aabb")  # fmt: skip
    for at, row in enumerate(rows.tolist()):
        assert write(row, at) == reduced.write_overlay(batch, old, row, servos, at)
        assert new.opt.timestep == old.opt.timestep
        for name in fields:
            np.testing.assert_array_equal(getattr(new, name), getattr(old, name), err_msg=name)
