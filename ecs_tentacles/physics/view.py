"""One creature's physics, seen through its batch's arrays (for scripts, tools and tests).

    view = world.physics.view_of(creature)     # or world.physics.views[i]
    view.data.qvel[:6]                          # its free joint's velocity (a view)
    view.data.xfrc_applied[view.body_ids[0], 2] = 50.0   # push its mantle up

`view.data` offers the MjData fields a script may read or write for one creature:
qpos, qvel, ctrl, eq_active, mocap_pos, mocap_quat (views into its state row), time,
xpos and xquat (its bodies' poses after the last step; poses are indexed by
`body_ids` as in MuJoCo) and xfrc_applied (forces applied before every step until set
back to zero). Nothing here runs per frame: the backend steps whole arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, overload

import mujoco
import numpy as np

if TYPE_CHECKING:
    from ecs_tentacles.physics.batch import Batch
    from ecs_tentacles.physics.roster import Roster

S = mujoco.mjtState


class StateView:
    """MjData-like access to one creature's row of a batch."""

    def __init__(self, batch: Batch, row: int):
        self._batch, self._row = batch, row

    def _part(self, flag: int) -> np.ndarray:
        self._batch.place_pending(self._row)  # (a row the build only showed)
        return self._batch.part(flag, self._row)

    @property
    def qpos(self) -> np.ndarray:
        return self._part(S.mjSTATE_QPOS)

    @property
    def qvel(self) -> np.ndarray:
        return self._part(S.mjSTATE_QVEL)

    @property
    def ctrl(self) -> np.ndarray:
        return self._part(S.mjSTATE_CTRL)

    @property
    def eq_active(self) -> np.ndarray:
        return self._part(S.mjSTATE_EQ_ACTIVE)

    @property
    def mocap_pos(self) -> np.ndarray:
        return self._part(S.mjSTATE_MOCAP_POS).reshape(-1, 3)

    @property
    def mocap_quat(self) -> np.ndarray:
        return self._part(S.mjSTATE_MOCAP_QUAT).reshape(-1, 4)

    @property
    def time(self) -> float:
        return float(self._part(S.mjSTATE_TIME)[0])

    @time.setter
    def time(self, value: float) -> None:
        self._part(S.mjSTATE_TIME)[0] = value

    @property
    def xpos(self) -> np.ndarray:
        """World positions by MuJoCo body id (the creature's bodies; others zero), as
        shown now (replayed: as the replay placed them)."""
        return self._by_body_id(self._batch.poses(self._row)[0], 3)

    @property
    def xquat(self) -> np.ndarray:
        return self._by_body_id(self._batch.poses(self._row)[1], 4)

    def _by_body_id(self, values: np.ndarray, width: int) -> np.ndarray:
        out = np.zeros((self._batch.model.nbody, width))
        out[self._batch.body_ids] = values
        return out

    @property
    def deepest_contact(self) -> float:
        """The deepest contact distance of the last step (m; < 0 penetrates; inf: none)."""
        return float(self._batch.deepest[self._row])

    @property
    def xfrc_applied(self) -> np.ndarray:
        """Forces (nbody, 6) applied to this creature before each step, until zeroed."""
        applied = self._batch.applied.get(self._row)
        if applied is None:
            applied = self._batch.applied[self._row] = np.zeros((self._batch.model.nbody, 6))
        return applied


class CreatureView:
    """One creature's place in the physics: its batch, its row and its ids."""

    def __init__(self, roster: Roster, index: int):
        self._roster = roster
        self.index = index  # the creature's position in the roster's arrays
        self.creature = int(roster.entity[index])
        self.creatures = [self.creature]
        self.creature_row = int(roster.creature_row[index])
        self.batch, self.row = roster.locate(index)

    @property
    def model(self) -> mujoco.MjModel:
        """The morphology's shared model (never write it: use the view's data)."""
        return self.batch.model

    @property
    def data(self) -> StateView:
        return StateView(self.batch, self.row)

    def standalone(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """A new MjModel and MjData of this creature alone, as its next step sees them."""
        return self.batch.standalone(self.row)

    def integration_state(self) -> np.ndarray:
        """A copy of this creature's state row (`physics.batch.STATE`)."""
        self.batch.place_pending(self.row)
        return np.asarray(self.batch.state[self.row].copy())

    @property
    def kp(self) -> np.ndarray:
        """Servo stiffness per actuator as the next step uses it (strength x gain x soften)."""
        return np.asarray(self.batch.kp[self.row])

    @property
    def kv(self) -> np.ndarray:
        """Servo damping per actuator (damping x gain)."""
        return np.asarray(self.batch.kv[self.row])

    @property
    def torque(self) -> np.ndarray:
        """Torque limit per actuator."""
        return np.asarray(self.batch.torque[self.row])

    @property
    def proxy_mocap(self) -> np.ndarray:
        return np.asarray(self.batch.proxy_mocap)

    @property
    def body_ids(self) -> np.ndarray:
        return self.batch.body_ids

    @property
    def body_rows(self) -> np.ndarray:
        return np.asarray(self.batch.body_rows[self.row])

    @property
    def actuator_motor_rows(self) -> np.ndarray:
        return np.asarray(self.batch.actuator_motor_rows[self.row])

    @property
    def equality_ids(self) -> np.ndarray:
        return self.batch.equality_ids

    @property
    def sucker_rows(self) -> np.ndarray:
        return np.asarray(self.batch.sucker_rows[self.row])

    @property
    def frozen(self) -> bool:
        return bool(self._roster.frozen[self.index])

    @property
    def sleeping(self) -> bool:
        return bool(self._roster.sleeping[self.index])

    @property
    def soften(self) -> float:
        return float(self._roster.soften[self.index])

    @property
    def active(self) -> bool:
        return not (self.frozen or self.sleeping)

    @property
    def proxies_used(self) -> int:
        return int(self._roster.proxies_used[self.index])

    def __repr__(self) -> str:
        state = "frozen" if self.frozen else "asleep" if self.sleeping else "active"
        bodies = len(self.body_ids)
        return f"<creature {self.index} physics: {bodies} bodies, {self.model.nv} dofs, {state}>"


class CreatureViews(Sequence[CreatureView]):
    """`physics.views`: each creature's `CreatureView`, by roster index, made when asked
    (a spawn or despawn into a big crowd makes none)."""

    def __init__(self, roster: Roster):
        self._roster = roster
        self._made: dict[int, CreatureView] = {}

    def __len__(self) -> int:
        return len(self._roster)

    @overload
    def __getitem__(self, index: int) -> CreatureView: ...
    @overload
    def __getitem__(self, index: slice) -> list[CreatureView]: ...
    def __getitem__(self, index: int | slice) -> CreatureView | list[CreatureView]:
        if isinstance(index, slice):
            return [self[i] for i in range(len(self))[index]]
        count = len(self)
        if not -count <= index < count:
            raise IndexError(f"creature {index}: the physics has {count}")
        index %= count
        view = self._made.get(index)
        if view is None:
            view = self._made[index] = CreatureView(self._roster, index)
        return view
