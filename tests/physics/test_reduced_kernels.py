"""The reduced tier's map kernel gives numpy's numbers bit for bit, at the edges too."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ecs_tentacles.physics import reduced as reduced_module
from ecs_tentacles.physics.reduced import ReducedModel
from ecs_tentacles.physics.tiers import REDUCED
from ecs_tentacles.world import World

SCENE = {
    "version": 1,
    "creatures": [{"name": "c", "position": [0.0, 0.0], "tentacles": {"count": 3, "links": 6}}],
}


@pytest.fixture
def reduced(make_world: Callable[..., World]) -> ReducedModel:
    world = make_world(SCENE)
    batch = world.physics.batches[0]
    batch.prepare(REDUCED, 1)
    assert batch.reduced is not None
    return batch.reduced


def _states(width: int, rows: int, seed: int, limit: float) -> np.ndarray:
    """`rows` states of `width` entries: ordinary values, values past the joints' limits
    both ways, and the edges (NaN, infinities, signed zeros, the limit itself and one ulp
    beside it)."""
    rng = np.random.default_rng(seed)
    states = rng.normal(0.0, 0.5, (rows, width))
    states[:, 1::3] *= 40.0  # far past any limit: clipped
    beside = [np.nextafter(limit, np.inf), np.nextafter(-limit, -np.inf)]
    edges = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, limit, -limit, *beside, 1e-300])
    for row in range(rows):
        at = rng.choice(width, size=min(width, len(edges)), replace=False)
        states[row, at] = edges[: len(at)]
    return states


@pytest.mark.parametrize("rows", [0, 1, 7])
def test_the_maps_are_numpys_bit_for_bit(
    reduced: ReducedModel, monkeypatch: pytest.MonkeyPatch, rows: int
) -> None:
    assert reduced_module.KERNELS.get() is not None  # numba comes with the dev extra
    full_width = max(s.stop for s in reduced.full_slices.values())
    limit = float(reduced.limit[0])
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
        full = _states(full_width, rows, 1, limit)
        pulled = np.full((rows, reduced.size), -7.0)
        small = _states(reduced.size, rows, 2, limit)
        shown = np.full((rows, full_width), -7.0)
        one = np.full(full_width, -7.0)
        with np.errstate(all="ignore"):  # infinity x 0 is NaN, on purpose
            reduced.pull_rows(full, pulled)
            reduced.expand_rows(small, shown)
            if rows:
                reduced.expand_state(small[0], one)
        results.append((pulled, shown, one))
    for kernel, numpy in zip(*results, strict=True):
        assert kernel.tobytes() == numpy.tobytes()  # bits: NaN and -0.0 included
    pulled, shown, _ = results[0]
    if rows:
        assert not (pulled == -7.0).all() and np.isnan(shown).any()  # edges reached the maps
        angles = shown[:, reduced._angles[1]]
        finite = angles[np.isfinite(angles)]
        assert (np.abs(finite) <= reduced.limit.max()).all()  # clipped into the limits
        assert (np.abs(finite) == reduced.limit.max()).any()


@pytest.mark.parametrize("rows", [0, 1, 9])
def test_the_servos_are_numpys_bit_for_bit(
    reduced: ReducedModel, monkeypatch: pytest.MonkeyPatch, rows: int
) -> None:
    actuators = int(reduced.full_u.max()) + 1
    rng = np.random.default_rng(3)
    kp = rng.uniform(5.0, 40.0, (rows, actuators))  # the schema's strengths
    kv = rng.uniform(0.05, 2.0, (rows, actuators))
    torque = rng.uniform(1.0, 5.0, (rows, actuators))
    edges = [np.nan, np.inf, 0.0, -0.0, -3.0, 1e-12, np.nextafter(1e-12, 0.0), 1e-300]
    for row in range(rows):  # an edge in some rows' groups, the rest ordinary
        at = rng.choice(reduced.full_u, size=len(edges), replace=False)  # in the groups
        kp[row, at] = edges if row % 3 == 1 else kp[row, at]
        kv[row, at] = edges if row % 3 == 2 else kv[row, at]
    if rows > 3:
        kp[3] *= 1e4  # stiff: the step split in several
        kp[4] = 1e12  # past any schema value: the most splits
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
        with np.errstate(all="ignore"):
            servos = reduced.servos(kp, kv, torque)
        results.append(servos)
    kernel, numpy = results
    for name in ("kp", "kv", "torque", "split"):
        got, want = getattr(kernel, name), getattr(numpy, name)
        assert got.dtype == want.dtype and got.shape == want.shape
        assert got.tobytes() == want.tobytes(), name
    if rows > 4:
        assert kernel.split[3] > 1 and kernel.split[4] == reduced_module.MAX_SPLIT
        assert np.isnan(kernel.kp[1]).any() and not np.isnan(kernel.kp[0]).any()
        assert np.isnan(kernel.kv[2]).any()  # the edges reached the kernel's gains


def test_a_rows_overlay_is_numpys_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The servos and sucker anchors a reduced row's step reads from the scratch model,
    written by the kernel and by numpy: the same model arrays, for every row."""
    from ecs_tentacles.creator.crowd import crowd_scene

    world = make_world(crowd_scene(6, seed=2))  # several body plans, suckers on every link
    world.step(3)
    batch = world.physics.batches[0]
    batch.prepare(REDUCED, 1)
    reduced = batch.reduced
    assert reduced is not None and len(batch.equality_ids)
    rng = np.random.default_rng(0)
    batch.anchor[:] = rng.normal(size=batch.anchor.shape)  # as if each row's suckers held
    rows = np.arange(len(batch.members))
    batch.kp[rows] *= rng.uniform(0.5, 2.0, size=batch.kp[rows].shape)  # each row its own
    servos = reduced.servos(batch.kp[rows], batch.kv[rows], batch.torque[rows])
    m = batch.scratch_for(0, REDUCED).model
    for at, row in enumerate(rows.tolist()):
        written = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
            for name in ("actuator_gainprm", "actuator_biasprm", "actuator_forcerange", "eq_data"):
                getattr(m, name)[:] = -7.0
            split = reduced.write_overlay(batch, m, row, servos, at)
            written.append([split, m.opt.timestep, m.actuator_gainprm.copy(),
                            m.actuator_biasprm.copy(), m.actuator_forcerange.copy(),
                            m.eq_data.copy()])  # fmt: skip
        for kernel, numpy_path in zip(*written, strict=True):
            np.testing.assert_array_equal(kernel, numpy_path)
        assert (written[0][5][reduced.equality_ids, 3:6] == batch.anchor[row]).all()


def test_a_shares_rows_are_pulled_and_shown_as_numpy_does_bit_for_bit(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A share's rows, in place: the frame's inputs pulled into the reduced states of the
    rows whose full state is as their last step left it (the others, written from outside,
    handed back to be fitted), their servos picked by row, and stepped states shown on
    the full skeleton with the compared part kept: the kernels' bits are numpy's."""
    from ecs_tentacles.creator.crowd import crowd_scene

    world = make_world(crowd_scene(6, seed=2, uniform=True))  # one body plan: one batch
    world.step(3)
    batch = world.physics.batches[0]
    batch.prepare(REDUCED, 1)
    reduced = batch.reduced
    assert reduced is not None and len(batch.members) >= 5
    rng = np.random.default_rng(4)
    state = rng.normal(0.0, 0.5, (len(batch.members), batch.state.shape[1]))
    rstate: np.ndarray = rng.normal(0.0, 0.5, (len(batch.members), reduced.size))
    rsource = state[:, reduced.watched].copy()
    rsource[1, 3] += 1e-9  # row 1's full state was written from outside
    rsource[3, 0] = np.nan  # and row 3's holds a NaN: never "as its step left it"
    state[3, reduced.watched.start] = np.nan
    rows = np.array([4, 1, 3, 0])  # a share, in the order the plan hands it out
    slot_of = rng.permutation(len(rstate))  # each row's reduced state: its slot of the pool
    pool, source_pool = np.empty_like(rstate), np.empty_like(rsource)
    pool[slot_of], source_pool[slot_of] = rstate, rsource
    slots = slot_of[rows]
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
        mine = [state.copy(), pool.copy(), source_pool.copy()]
        refit = reduced.pull_into(rows, slots, mine[0], mine[1], mine[2])
        servos = reduced.servos(batch.kp, batch.kv, batch.torque, rows)
        stepped = mine[1] + 0.25  # as if the rows stepped
        reduced.show_rows(rows[[0, 3]], slots[[0, 3]], stepped, mine[0], mine[2])
        results.append((refit, servos.kp, servos.kv, servos.torque, servos.split, *mine))
    for kernel, numpy_path in zip(*results, strict=True):
        assert kernel.dtype == numpy_path.dtype and kernel.tobytes() == numpy_path.tobytes()
    refit, kp, *_ = results[0]
    assert rows[refit].tolist() == [1, 3]  # written from outside: fitted, not pulled
    shown_state, pulled, kept = results[0][5:]
    assert not np.array_equal(pulled[slot_of[4]], rstate[4])
    assert np.array_equal(pulled[slot_of[1]], rstate[1])
    assert np.array_equal(kept[slot_of[4]], shown_state[4, reduced.watched])  # kept to compare
    assert np.array_equal(kp, reduced.servos(batch.kp[rows], batch.kv[rows], batch.torque[rows]).kp)


def test_a_shares_step_costs_are_numpys_bit_for_bit(monkeypatch: pytest.MonkeyPatch) -> None:
    """The running mean of the reduced rows' step times (for sharing rows between
    threads): first measures taken as they are, later ones averaged in."""
    from ecs_tentacles.physics.batch import running_costs

    rng = np.random.default_rng(6)
    start = rng.uniform(1e-5, 1e-3, (9, 3))
    start[[2, 5], REDUCED] = 0.0  # never measured yet
    rows, took = np.array([5, 0, 2, 7]), rng.uniform(1e-5, 1e-3, 4)
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(reduced_module.KERNELS, "backend", backend)
        cost = start.copy()
        running_costs(cost, rows, REDUCED, took, 3e-6, 2)
        found.append(cost)
    assert found[0].tobytes() == found[1].tobytes()
    assert found[0][5, REDUCED] == (took[0] + 3e-6) / 2  # the first measure, as it is
    assert found[0][0, REDUCED] == 0.75 * start[0, REDUCED] + 0.25 * (took[1] + 3e-6) / 2
    assert np.array_equal(found[0][[1, 3, 4, 6, 8]], start[[1, 3, 4, 6, 8]])
