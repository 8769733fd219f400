"""The REDUCED tier's model: about half the links per tentacle at an eighth of the rate.

The reduced creature's body is built in `physics.reduced_body`, the maps below in
`physics.reduced_maps`; it steps at an eighth of the scene's rate
(`tiers.reduced_substeps`: 60 Hz, one step a frame, at the default 480 Hz).

`ReducedModel` maps states between the two models, tentacle by tentacle and hinge axis
by hinge axis, through each link's heading along the tentacle (the sum of its joint
angles from the mantle): a reduced chain is shown as the full chain whose headings are
the reduced ones interpolated at the full links' centres (`expand`: a smooth curve
through the reduced links, sampled at the full links), and a full chain becomes the
reduced chain whose links' ends and headings are nearest its own (`fit`, least
squares). Servo targets are fitted the same way. A reduced servo, at its group's first
joint, is as stiff as its group's servos are against a force at the tentacle's tip
(the load of a gripping stroke): full joint i, d_i from the tip, lets the tip give
d_i^2 / kp_i, so the reduced servo's kp is d_1^2 / sum(d_i^2 / kp_i) (`compliance`),
times `STIFFNESS_GAIN`; it is damped likewise, times `DAMPING_GAIN` (the part above
`STIFFNESS_GAIN` at most `DAMPING_CAP` of critical damping), and as strong as the first
of them. A row whose servos are too stiff for the reduced step takes shorter ones
(`STIFF_STEP`).

The batch keeps every creature's state in the full model's layout, so drawing,
export, health, sleep, snapshots and the contact proxies never see a reduced model: a
REDUCED row keeps a second state (`Batch.rstate`, at its row's `Batch.rslot`: only rows
that step REDUCED hold one) that `step_rows` fits again whenever
the full state was written from outside (a recovery, a promotion from replay, a
restore), steps, and shows as the full state (joint angles expanded, poses from the
full model's kinematics).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.physics.reduced_maps import (
    block_diagonal,
    expansion,
    group_sums,
    padded,
    reduced_body,
    tip_compliance,
)
from ecs_tentacles.physics.state_layout import STATE, Rows, size_proxies, state_slices

if TYPE_CHECKING:
    from ecs_tentacles.physics.reduced_body import Chain


@dataclass(frozen=True)
class Servos:
    """Some rows' reduced servos (`ReducedModel.servos`), row by row: gains, torque limits
    and the number of shorter steps each row's step is split in (`STIFF_STEP`)."""

    kp: np.ndarray  # (rows, reduced servos)
    kv: np.ndarray
    torque: np.ndarray
    split: np.ndarray  # (rows,) int


S = mujoco.mjtState
# the maps and servo gains by numba when installed (`physics.reduced_kernels`); =numpy: numpy
KERNELS = OptionalKernels("ecs_tentacles.physics.reduced_kernels", "ECS_TENTACLES_REDUCED")
# The reduced servos' gains over the full ones' (module docstring). The servos in series
# (stiffness 1 / sum 1 / kp) had to be softened to 0.8 to crawl as fast as the full
# creature, and softening is not the same everywhere: under a heavy mantle the reduced
# tentacles sagged more, so creature by creature the reduced progress spread 0.66-1.43
# (sd 0.110 of the ratio, correlation -0.54 with the mantle radius: 128 creatures of 32
# body plans, 10 s, far apart). Matched at the tip (stiffer toward it), a reduced chain
# moves to its targets faster than the ten servos it stands for (22 % more progress at
# gain 1): damping, which does not depend on the load, slows it back. At 0.9 and 2:
# progress 1.03 of full, sd 0.088, correlation -0.22; the crossing crowd of
# `tools/lod_fidelity.py --goals-within 0.8` arrives within 2 s for 60 of 61 creatures
# (seed 0; 56 before), 55 of 61 (seed 1; 53 of 59) and 61 of 62 (seed 2; 60 of 62).
# Those figures were taken at 120 Hz. At 60 Hz (one step a frame, `tiers.REDUCED_RATE`)
# damping 2 made a heavy-mantled creature slower than its full self (0.74-0.99 at mantle
# radius 0.19, 0.84-1.03 at 0.12; 120 Hz: 1.04-1.14); damping 1.5 gives 0.99-1.05 and
# 1.07-1.10, and the crossing crowd of `tools/lod_fidelity.py` 0.983 of full progress
# at 64 creatures (0.975 with damping 2).
STIFFNESS_GAIN = 0.9
DAMPING_GAIN = 1.5
# The damping DAMPING_GAIN adds over STIFFNESS_GAIN's share is at most DAMPING_CAP of the
# hinge's critical damping (2 sqrt(kp I), I its inertia at rest): it calms the faster
# swing of a chain matched at the tip, an inertial effect. A heavily damped servo is not
# swinging but creeping, at kp / kv, and doubled damping slowed it: default octopuses
# with damping 2, 5 and 25 crawled reduced at 0.92, 0.66 and 0.70 of their full selves,
# now 1.08, 1.06 and 1.28 (`tools/reduced_pace.py --servos`, docs/crowds.md). The
# crowd barely moves (1.04 of full, sd 0.089 over the tool's 128 creatures; 1.03 and
# 0.088 without the cap).
DAMPING_CAP = 1.0
# The stiffest a reduced servo may be at the reduced step h: kp h^2 / I <= STIFF_STEP, I
# the hinge's inertia at rest (`dof_M0`). Stiffer rows take shorter steps, as many more
# as it needs (`write_overlay`). At 120 Hz default creatures (strength 25) were at 0.47
# and the step failed from 9.4 (strength 500 and damping 1.1 to 3, a default body) and
# held at 7.6 (strength 400): 4 is the undamped limit of the integrator (omega h <= 2).
# At 60 Hz (four times h^2) the crowd generator's creatures are at 0.8-4.6: 3 of a varied
# crowd's 64 take two steps a frame, a uniform crowd's none.
STIFF_STEP = 4.0
# A row with another creature near (its contact proxies in use) takes at least NEAR_SPLIT
# steps a frame: at one step a frame a contact's time constant is 33 ms (two steps), and
# a reduced creature squeezed between neighbours (the 4 x 4 crossing crowd of
# tests/physics/test_contacts.py with crowd avoidance off, 20 s) went 12 mm into one with
# a recovery (28 mm and 15 recoveries with the full tier's proxy margin); two steps keep
# it 8 mm apart with none, as full physics keeps it 6 mm apart. Only rows near another
# pay for it.
NEAR_SPLIT = 2
MAX_SPLIT = 64  # at most this many shorter steps (a script's gain far past the schema's)
_NO_CLIP = np.zeros(0)  # the map kernel's bounds when a map is not clipped
_NO_EQUALITIES = np.zeros(0, dtype=np.int64)  # the overlay kernel's, without suckers


class ReducedModel:
    """A batch's reduced model and the maps between its states and the full model's."""

    def __init__(self, full: mujoco.MjModel, model: mujoco.MjModel, tentacles: list[Chain]):
        self.model = model
        self.full_slices = state_slices(full)
        self.slices = state_slices(model)
        full_q, red_q, full_v, red_v, full_u, red_u = [], [], [], [], [], []
        blocks_e, blocks_f, weights, first, limits = [], [], [], [], []
        offset = 0  # full hinges so far
        for chain in tentacles:
            for axis in chain.axes:
                full_names = [
                    f"t{chain.tentacle}/l{i:02d}/{axis}" for i in range(len(chain.lengths))
                ]
                red_names = [f"t{chain.tentacle}/l{k:02d}/{axis}" for k in range(len(chain.groups))]
                fj = [full.joint(n) for n in full_names]
                rj = [model.joint(n) for n in red_names]
                full_q += [int(j.qposadr[0]) for j in fj]
                full_v += [int(j.dofadr[0]) for j in fj]
                red_q += [int(j.qposadr[0]) for j in rj]
                red_v += [int(j.dofadr[0]) for j in rj]
                full_u += [full.actuator(n).id for n in full_names]
                red_u += [model.actuator(n).id for n in red_names]
                limits += [float(j.range[1]) for j in fj]
                expand, fit = expansion(chain)
                blocks_e.append(expand)
                blocks_f.append(fit)
                weights.append(tip_compliance(chain))
                first += [offset + int(g[0]) for g in chain.groups]
                offset += len(chain.lengths)
        self.expand = block_diagonal(blocks_e)  # (full hinges, reduced hinges)
        self.fit = block_diagonal(blocks_f)  # (reduced hinges, full hinges)
        # reduced hinge <- its group's full hinges, each weighted (d_i / d_1)^2
        self.compliance = block_diagonal(weights)
        # the three maps as padded group sums (`group_sums`: a row's bits whatever rows
        # share the call)
        self._members, self._weights = padded(self.compliance)
        self._fit_sums, self._expand_sums = padded(self.fit), padded(self.expand)
        self.first = np.array(first, dtype=np.int64)  # each reduced hinge's first full one
        self.limit = np.array(limits)
        self.full_q, self.red_q = np.array(full_q), np.array(red_q)
        self.full_v, self.red_v = np.array(full_v), np.array(red_v)
        self.full_u, self.red_u = np.array(full_u), np.array(red_u)
        self.root_q = int(full.joint("root").qposadr[0])
        self.root_v = int(full.joint("root").dofadr[0])
        self.red_root_q = int(model.joint("root").qposadr[0])
        self.red_root_v = int(model.joint("root").dofadr[0])
        self.size = mujoco.mj_stateSize(model, STATE)
        # the part of a full state a reduced step writes, to know when someone else did
        q, v = self.full_slices[int(S.mjSTATE_QPOS)], self.full_slices[int(S.mjSTATE_QVEL)]
        self.watched = slice(q.start, v.stop)
        # the state entries each map reads and writes, as index arrays: one gather a map
        rs, fs = self.slices, self.full_slices

        def entries(slices: dict[int, slice], flags: tuple[mujoco.mjtState, ...]) -> np.ndarray:
            parts = [slices[int(f)] for f in flags]
            return np.concatenate([np.arange(p.start, p.stop) for p in parts])

        inputs = (S.mjSTATE_TIME, S.mjSTATE_EQ_ACTIVE, S.mjSTATE_MOCAP_POS, S.mjSTATE_MOCAP_QUAT)
        self._inputs = (entries(fs, inputs), entries(rs, inputs))  # (full, reduced)
        self._controls = (
            fs[int(S.mjSTATE_CTRL)].start + self.full_u,
            rs[int(S.mjSTATE_CTRL)].start + self.red_u,
        )
        rq, rv = rs[int(S.mjSTATE_QPOS)], rs[int(S.mjSTATE_QVEL)]
        fq, fv = fs[int(S.mjSTATE_QPOS)], fs[int(S.mjSTATE_QVEL)]
        self._shown = (  # (reduced, full): the clock and the root, copied
            np.concatenate([
                np.arange(rs[int(S.mjSTATE_TIME)].start, rs[int(S.mjSTATE_TIME)].stop),
                rq.start + np.arange(self.red_root_q, self.red_root_q + 7),
                rv.start + np.arange(self.red_root_v, self.red_root_v + 6),
            ]),
            np.concatenate([
                np.arange(fs[int(S.mjSTATE_TIME)].start, fs[int(S.mjSTATE_TIME)].stop),
                fq.start + np.arange(self.root_q, self.root_q + 7),
                fv.start + np.arange(self.root_v, self.root_v + 6),
            ]),
        )  # fmt: skip
        self._angles = (rq.start + self.red_q, fq.start + self.full_q)
        self._speeds = (rv.start + self.red_v, fv.start + self.full_v)
        # the same for the row kernels: pairs stacked, slices as (start, stop)
        self._input_pairs, self._shown_pairs = np.vstack(self._inputs), np.vstack(self._shown)
        self._watched = np.array([self.watched.start, self.watched.stop])
        warm = self.full_slices[int(S.mjSTATE_WARMSTART)]
        self._warm = np.array([warm.start, warm.stop])
        self._torque_u = self.full_u[self.first]
        self.timestep = float(model.opt.timestep)
        # kp h^2 / I of each reduced servo per unit kp (STIFF_STEP)
        self._stiff_per_kp = self.timestep**2 / model.dof_M0[self.red_v]
        self._critical_per_sqrt_kp = 2.0 * np.sqrt(model.dof_M0[self.red_v])
        self._low = -self.limit
        obj = mujoco.mjtObj
        names = [mujoco.mj_id2name(full, obj.mjOBJ_BODY, b) for b in range(full.nbody)]
        self.body_group = np.zeros((model.nbody, full.nbody))  # applied forces: summed
        for b, name in enumerate(names):
            target = reduced_body(name, tentacles)
            if target is not None:
                self.body_group[model.body(target).id, b] = 1.0

    # -- states ----------------------------------------------------------------------
    def fit_state(self, full_state: np.ndarray, out: np.ndarray) -> None:
        """`out` (a reduced state) nearest the full state `full_state`; warm start cleared."""
        fs, rs = self.full_slices, self.slices
        out[:] = 0.0
        fq, rq = full_state[fs[int(S.mjSTATE_QPOS)]], out[rs[int(S.mjSTATE_QPOS)]]
        fv, rv = full_state[fs[int(S.mjSTATE_QVEL)]], out[rs[int(S.mjSTATE_QVEL)]]
        rq[self.red_root_q : self.red_root_q + 7] = fq[self.root_q : self.root_q + 7]
        rv[self.red_root_v : self.red_root_v + 6] = fv[self.root_v : self.root_v + 6]
        rq[self.red_q] = self.fit @ fq[self.full_q]
        rv[self.red_v] = self.fit @ fv[self.full_v]
        self.pull_inputs(full_state, out)

    def pull_into(
        self,
        rows: np.ndarray,
        slots: np.ndarray,
        state: np.ndarray,
        rstate: np.ndarray,
        rsource: np.ndarray,
    ) -> np.ndarray:
        """The frame's inputs pulled into the reduced states of batch rows `rows` (rows
        `slots` of `rstate`, in place; `state` the batch's full states) where the full
        state is still as their last step left it (`rsource`, the watched part, at
        `slots`); returns the positions in `rows` of the others, whose full state was
        written from outside since (to fit again)."""
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, row by row in place: no gathered copies
            changed = np.zeros(len(rows), dtype=bool)
            commands, servos = self._controls
            fast.pull_into(rows, slots, state, rsource, self._watched, rstate,
                           self._input_pairs, commands, *self._fit_sums, servos,
                           changed)  # fmt: skip
            return np.flatnonzero(changed)
        unchanged = (state[rows, self.watched] == rsource[slots]).all(axis=1)
        pulled = slots[unchanged]
        if len(pulled):
            block = rstate[pulled]
            self.pull_rows(state[rows[unchanged]], block)
            rstate[pulled] = block
        return np.flatnonzero(~unchanged)

    def show_rows(
        self,
        rows: np.ndarray,
        slots: np.ndarray,
        rstate: np.ndarray,
        state: np.ndarray,
        rsource: np.ndarray,
    ) -> None:
        """Batch rows `rows`' reduced states (rows `slots` of `rstate`) shown as their full
        states (`state`, in place: `expand_rows`), and the watched part kept in `rsource`
        (at `slots`: what `pull_into` compares with next time)."""
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, row by row in place: no gathered copies
            fast.show_rows(rows, slots, rstate, state, self._shown_pairs, *self._angles,
                           *self._speeds, *self._expand_sums, self._low, self.limit, self._warm,
                           self._watched, rsource)  # fmt: skip
            return
        block = state[rows]
        self.expand_rows(rstate[slots], block)
        state[rows] = block
        rsource[slots] = block[:, self.watched]

    def pull_inputs(self, full_state: np.ndarray, out: np.ndarray) -> None:
        """What the systems wrote into the full state this frame (servo targets fitted,
        sucker switches, proxy poses, the clock) into the reduced state `out`."""
        self.pull_rows(full_state[None], out[None])

    def pull_rows(self, full_states: np.ndarray, out: np.ndarray) -> None:
        """`pull_inputs` of many rows at once: (rows, full state) into (rows, reduced
        state) `out`, in place; each row's bits as if pulled alone."""
        source, target = self._inputs
        out[:, target] = full_states[:, source]
        source, target = self._controls
        fast = KERNELS.get()
        if fast is not None:  # the same sums, the interpreter's lock released
            every = np.arange(len(out))
            fast.group_sums_into(full_states, every, source, *self._fit_sums,
                                 _NO_CLIP, _NO_CLIP, out, every, target)  # fmt: skip
            return
        out[:, target] = group_sums(full_states[:, source], *self._fit_sums)

    def expand_state(self, reduced_state: np.ndarray, out: np.ndarray) -> None:
        """The full state `out` shows the reduced state: root and clock copied, joint
        angles and speeds expanded (within the full joints' limits), warm start cleared."""
        self.expand_rows(reduced_state[None], out[None])

    def expand_rows(self, reduced_states: np.ndarray, out: np.ndarray) -> None:
        """`expand_state` of many rows at once: (rows, reduced state) into (rows, full
        state) `out`, in place; each row's bits as if expanded alone."""
        source, target = self._shown
        out[:, target] = reduced_states[:, source]
        fast = KERNELS.get()
        if fast is not None:  # the same sums and clip, the interpreter's lock released
            rows = np.arange(len(out))
            source, target = self._angles
            fast.group_sums_into(reduced_states, rows, source, *self._expand_sums, self._low,
                                 self.limit, out, rows, target)  # fmt: skip
            source, target = self._speeds
            fast.group_sums_into(reduced_states, rows, source, *self._expand_sums, _NO_CLIP,
                                 _NO_CLIP, out, rows, target)  # fmt: skip
        else:
            source, target = self._angles
            angles = group_sums(reduced_states[:, source], *self._expand_sums)
            out[:, target] = np.minimum(np.maximum(angles, self._low, out=angles), self.limit)
            source, target = self._speeds
            out[:, target] = group_sums(reduced_states[:, source], *self._expand_sums)
        out[:, self.full_slices[int(S.mjSTATE_WARMSTART)]] = 0.0

    # -- model values ----------------------------------------------------------------
    def servos(
        self, kp: np.ndarray, kv: np.ndarray, torque: np.ndarray, rows: np.ndarray | None = None
    ) -> Servos:
        """The reduced servos of rows whose full servos have gains `kp`, `kv` and torque
        limits `torque` (rows, full actuators; with `rows`, of those rows of them only,
        in that order): each reduced one its group's, matched at
        the tip, and each row's step split in as many as its stiffest servo needs
        (`STIFF_STEP`; 1 but for servos far stiffer than a default creature's, and where a
        gain is not finite: the health check sees that failure). Summed group member by
        group member, not by a matrix product, so a row gets the same bits whatever rows
        it is computed with (a frame's rows are shared among threads as they free up)."""
        fast = KERNELS.get()
        if fast is not None:  # the same numbers, the interpreter's lock released
            picked = np.arange(len(kp)) if rows is None else rows
            count, servos = len(picked), len(self._members)
            gains, damping = np.empty((count, servos)), np.empty((count, servos))
            split = np.empty(count, dtype=np.int64)
            # read now, as numpy's path does: a tool may set another reduced model's gains
            constants = np.array(
                [STIFFNESS_GAIN, DAMPING_GAIN, DAMPING_CAP, STIFF_STEP, MAX_SPLIT], np.float64
            )
            fast.servos(picked, kp, kv, self.full_u, self._members, self._weights,
                        self._stiff_per_kp, self._critical_per_sqrt_kp, constants,
                        gains, damping, split)  # fmt: skip
            return Servos(gains, damping, torque[picked[:, None], self._torque_u], split)
        if rows is not None:
            kp, kv, torque = kp[rows], kv[rows], torque[rows]
        full = self.full_u
        compliance = group_sums(1.0 / np.maximum(kp[:, full], 1e-12), self._members, self._weights)
        gains = STIFFNESS_GAIN / compliance
        stiff = np.max(gains * self._stiff_per_kp, axis=1)
        split = np.ones(len(gains), dtype=np.int64)
        far = (stiff > STIFF_STEP) & (stiff < np.inf)
        split[far] = np.minimum(np.ceil(np.sqrt(stiff[far] / STIFF_STEP)), MAX_SPLIT)
        matched = group_sums(1.0 / np.maximum(kv[:, full], 1e-12), self._members, self._weights)
        matched_kv = 1.0 / matched
        critical = np.sqrt(gains) * self._critical_per_sqrt_kp
        damping = np.minimum(
            DAMPING_GAIN * matched_kv, STIFFNESS_GAIN * matched_kv + DAMPING_CAP * critical
        )
        return Servos(gains, damping, torque[:, self._torque_u], split)

    def write_overlay(
        self, batch: Rows, m: mujoco.MjModel, row: int, servos: Servos, at: int
    ) -> int:
        """Row `row`'s servos (row `at` of `servos`), sucker anchors and proxy sizes into the
        reduced scratch model `m`, and its step split in as many shorter ones as `servos`
        says, that number returned."""
        split = int(servos.split[at])
        if batch.near[row]:
            split = max(split, NEAR_SPLIT)
        m.opt.timestep = self.timestep / split
        fast = KERNELS.get()
        if fast is not None:  # the same values in one call
            equalities = self.equality_ids if len(batch.equality_ids) else _NO_EQUALITIES
            fast.servo_overlay(m.actuator_gainprm, m.actuator_biasprm, m.actuator_forcerange,
                               self.red_u, servos.kp[at], servos.kv[at], servos.torque[at],
                               m.eq_data, equalities, batch.anchor[row])  # fmt: skip
        else:
            torque = servos.torque[at]
            u = self.red_u
            m.actuator_gainprm[u, 0] = servos.kp[at]
            m.actuator_biasprm[u, 1] = -servos.kp[at]
            m.actuator_biasprm[u, 2] = -servos.kv[at]
            m.actuator_forcerange[u, 0] = -torque
            m.actuator_forcerange[u, 1] = torque
            if len(batch.equality_ids):
                m.eq_data[self.equality_ids, 3:6] = batch.anchor[row]
        if batch.near[row]:
            size_proxies(m, self.proxy_geoms, batch.proxy_cylinder, batch.proxy_size[row])
        return split

    def overlay_writer(
        self, batch: Rows, m: mujoco.MjModel, servos: Servos
    ) -> Callable[[int, int], int]:
        """`write_overlay(batch, m, row, servos, at)` as a call `(row, at)` for the rows of
        one share, which go through it one after another: what it looks up in `m`,
        `batch` and `servos` is looked up once (each lookup makes a view: about 3 us a
        row, the interpreter's lock held). The same values into the same places."""
        fast = KERNELS.get()
        if fast is None:
            return lambda row, at: self.write_overlay(batch, m, row, servos, at)
        opt, timestep, u = m.opt, self.timestep, self.red_u
        gain, bias, limit, eq_data = (m.actuator_gainprm, m.actuator_biasprm,
                                      m.actuator_forcerange, m.eq_data)  # fmt: skip
        equalities = self.equality_ids if len(batch.equality_ids) else _NO_EQUALITIES
        splits, kp, kv, torque = servos.split.tolist(), servos.kp, servos.kv, servos.torque
        anchor, near, overlay = batch.anchor, batch.near, fast.servo_overlay

        def write(row: int, at: int) -> int:
            split: int = splits[at]
            if near[row]:
                split = max(split, NEAR_SPLIT)
            opt.timestep = timestep / split
            overlay(gain, bias, limit, u, kp[at], kv[at], torque[at], eq_data, equalities,
                    anchor[row])  # fmt: skip
            if near[row]:
                size_proxies(m, self.proxy_geoms, batch.proxy_cylinder, batch.proxy_size[row])
            return split

        return write

    def name_ids(self, batch: Rows, full: mujoco.MjModel) -> None:
        """The reduced model's ids of the batch's equalities and proxy geoms (same names)."""
        obj = mujoco.mjtObj
        self.equality_ids = np.array(
            [mujoco.mj_name2id(self.model, obj.mjOBJ_EQUALITY,
                               mujoco.mj_id2name(full, obj.mjOBJ_EQUALITY, int(e)))
             for e in batch.equality_ids], dtype=np.int64)  # fmt: skip
        self.proxy_geoms = np.array(
            [mujoco.mj_name2id(self.model, obj.mjOBJ_GEOM,
                               mujoco.mj_id2name(full, obj.mjOBJ_GEOM, int(g)))
             for g in batch.proxy_geoms], dtype=np.int64)  # fmt: skip
