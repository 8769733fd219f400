"""Where a batch's creatures start: each row placed at the build, or later, when first stepped.

`place(row, pos, quat)` writes a row's state (the mantle at `pos` / `quat`, every joint at
rest, the contact proxies parked) and its body poses at once: every creature of a small
world, and every spawned one. A crowd that replays most of its creatures from their first
frame (level of detail on, more creatures than the full budget) has most of them never
stepped, and a promotion from the replay writes the state a step reads again
(`PhysicsBackend.place_joints`); so the build only shows them (`show_placed`: the poses
into the Transform store, the state and pose rows untouched: `numeric.untouched`, no
memory taken) and remembers where (`placement`). A row is placed on demand
(`place_pending`) before anything reads or writes its state or its pose rows: the frame's
stepped rows after the level of detail decided, a promoted one, a view, a snapshot's
poses. Placed late, a row gets the very bits the build would have given it (the same
reset, the same forward kinematics), so a creature steps and is promoted the same.

Reads the batch's model and scratch (`Batch.scratch_for`); writes `state`, `xpos`,
`xquat` (placed rows), the Transform store (shown rows), `unplaced` and `placement`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from ecs_tentacles.numeric.untouched import untouched_zeros
from ecs_tentacles.physics.model import PROXY_PARKED
from ecs_tentacles.physics.state_layout import STATE
from ecs_tentacles.physics.tiers import KINEMATIC

if TYPE_CHECKING:
    from ecs_tentacles.physics.scratch import Scratch
    from ecs_tentacles.store import TransformStore


# rows not placed yet (None: all placed), where each is to be placed, the store showing them
PlacingState = tuple[np.ndarray | None, np.ndarray, "TransformStore | None"]


class Placing:
    """The placing side of a `Batch` (module docstring)."""

    state: np.ndarray  # (rows, state) each row's MuJoCo state
    xpos: np.ndarray  # (rows, bodies, 3) the last step's body positions
    xquat: np.ndarray  # (rows, bodies, 4)
    body_ids: np.ndarray
    body_rows: np.ndarray
    members: np.ndarray  # each row's creature index
    proxy_mocap: np.ndarray
    root_qpos: int
    # rows not placed yet (None: every row is placed), and where each is to be placed
    # (mantle pos, quat); their poses are in the store `placed_in`
    unplaced: np.ndarray | None
    placement: np.ndarray
    placed_in: TransformStore | None
    when_placed: Callable[[np.ndarray], None] | None  # told the rows `place_pending` placed

    if TYPE_CHECKING:

        def scratch_for(self, thread: int, tier: int = 0) -> Scratch: ...

        def _stepped(self, row: int) -> None: ...

    def _reset(self) -> mujoco.MjData:
        """Thread 0's scratch data reset, every joint at rest, proxies parked: each row's
        start but its mantle (`_kinematics` writes that). Reset once for many rows, not
        once a row (`mj_resetData` took 16 of a placing's 38 us): between rows only the
        root is written, and forward kinematics reads nothing it wrote for the row before."""
        scratch = self.scratch_for(0)
        m, d = scratch.model, scratch.data
        mujoco.mj_resetData(m, d)
        d.mocap_pos[self.proxy_mocap] = PROXY_PARKED
        return d

    def _kinematics(self, d: mujoco.MjData, pos: np.ndarray, quat: np.ndarray) -> None:
        """`d` (from `_reset`) with the mantle at `pos` / `quat`, its body poses computed."""
        d.qpos[self.root_qpos : self.root_qpos + 3] = pos
        d.qpos[self.root_qpos + 3 : self.root_qpos + 7] = quat
        # the poses are all a row needs here: forward kinematics gives them (and the
        # state read below is what was written above; mj_step writes the warm start),
        # a seventeenth of mj_forward's cost (contacts, constraints) per creature built
        mujoco.mj_kinematics(self.scratch_for(0).model, d)

    def _write_places(self, rows: Sequence[int], pos: np.ndarray, quat: np.ndarray) -> None:
        """Rows `rows`' state and pose rows, row i's mantle at pos[i] / quat[i]."""
        d, m = self._reset(), self.scratch_for(0).model
        for row, at, turn in zip(rows, pos, quat, strict=True):
            self._kinematics(d, at, turn)
            mujoco.mj_getState(m, d, self.state[row], STATE)
            self.xpos[row] = d.xpos[self.body_ids]
            self.xquat[row] = d.xquat[self.body_ids]

    def place(self, row: int, pos: np.ndarray, quat: np.ndarray) -> None:
        """Row `row`: the mantle at `pos` / `quat`, every joint at rest, proxies parked."""
        self.place_rows([row], np.reshape(pos, (1, 3)), np.reshape(quat, (1, 4)))

    def place_rows(self, rows: Sequence[int], pos: np.ndarray, quat: np.ndarray) -> None:
        """`place` of each of `rows` (`pos` (n, 3), `quat` (n, 4)): the same state and
        poses, the scratch data reset once (`_reset`)."""
        self._write_places(rows, pos, quat)
        for row in rows:
            if self.unplaced is not None:
                self.unplaced[row] = False
            self._stepped(row)

    def place_all(self, pos: np.ndarray, quat: np.ndarray, shown: TransformStore | None) -> None:
        """Every row at the build, row i's mantle at pos[i] / quat[i]: placed, or, given
        the store `shown`, only shown there (`show_placed`), the state and pose tables
        then anonymous mappings, resident for the rows written (`numeric.untouched`)."""
        pos, quat = pos.reshape(-1, 3).astype(np.float64), quat.reshape(-1, 4).astype(np.float64)
        if shown is not None:  # the tables resident for the rows written only
            self.state = untouched_zeros(self.state.shape)
            self.xpos, self.xquat = (
                untouched_zeros(self.xpos.shape),
                untouched_zeros(self.xquat.shape),
            )
            self.show_placed(np.arange(len(pos)), pos, quat, shown)
            return
        self.place_rows(range(len(pos)), pos, quat)

    def show_placed(self, rows: np.ndarray, pos: np.ndarray, quat: np.ndarray,
                    transforms: TransformStore) -> None:  # fmt: skip
        """Rows `rows` start with their mantles at pos[i] / quat[i] (as `place`), shown
        there in `transforms` only: their state and pose rows are written when first
        needed (`place_pending`)."""
        if self.unplaced is None:
            self.unplaced = np.zeros(len(self.body_rows), dtype=bool)
            self.placement = np.zeros((len(self.body_rows), 7))
        d = self._reset()
        for row, at, turn in zip(rows.tolist(), pos, quat, strict=True):
            self._kinematics(d, at, turn)
            store_rows = self.body_rows[row]
            transforms.pos[store_rows] = d.xpos[self.body_ids]
            transforms.quat[store_rows] = d.xquat[self.body_ids]
        self.unplaced[rows] = True
        self.placement[rows, :3], self.placement[rows, 3:] = pos, quat
        self.placed_in = transforms

    def pending(self, rows: np.ndarray) -> np.ndarray:
        """Those of `rows` not placed yet."""
        unplaced = self.unplaced
        return rows[unplaced[rows]] if unplaced is not None else rows[:0]

    def place_pending(self, rows: np.ndarray | int) -> np.ndarray:
        """Place those of `rows` not placed yet, where the build meant to (their shown
        poses stay as they are); the rows placed now."""
        late = self.pending(np.atleast_1d(np.asarray(rows, dtype=np.int64)))
        if not len(late):
            return late
        assert self.unplaced is not None
        self._write_places(late.tolist(), self.placement[late, :3], self.placement[late, 3:])
        self.unplaced[late] = False
        if self.when_placed is not None:
            self.when_placed(late)
        if not self.unplaced.any():
            self.unplaced, self.placement, self.placed_in = None, np.zeros((0, 7)), None
        return late

    def placing_state(self) -> PlacingState:
        """A copy of which rows are not placed yet and where they go (for snapshots)."""
        unplaced = None if self.unplaced is None else self.unplaced.copy()
        return unplaced, self.placement.copy(), self.placed_in

    def set_rows(
        self, state: np.ndarray, xpos: np.ndarray, xquat: np.ndarray, placing: PlacingState
    ) -> None:
        """Every row's state and poses back to `state`, `xpos`, `xquat` and `placing`
        (`placing_state()`), as saved: a row not placed then is placed when needed, its
        rows here left as they are (no pages for them)."""
        unplaced, placement, placed_in = placing
        placed = slice(None) if unplaced is None else np.flatnonzero(~unplaced)
        self.state[placed] = state[placed]
        self.xpos[placed], self.xquat[placed] = xpos[placed], xquat[placed]
        self.unplaced = None if unplaced is None else unplaced.copy()
        self.placement, self.placed_in = placement.copy(), placed_in


def place_stepped(batches: Sequence[Placing], tier: np.ndarray) -> None:
    """Place the rows of `batches` the build only showed whose creatures are not
    replayed this frame (`tier`, per creature); the replayed ones stay as they are."""
    stepped: np.ndarray | None = None
    for batch in batches:
        if batch.unplaced is None:
            continue
        if stepped is None:
            stepped = tier != KINEMATIC
        batch.place_pending(np.flatnonzero(stepped[batch.members]))
