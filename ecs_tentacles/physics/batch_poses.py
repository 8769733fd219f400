"""A batch's body poses as the world sees them (`physics.batch.Batch` is one): the poses
its last step produced (`xpos`, `xquat`, a row per creature), copied into the Transform
store each frame (`sync`), and the rows a replay wrote straight into the store instead
(`show`: one write, not two), read back from there (`poses`, `all_poses`), like the
rows the build only showed there (`unplaced`, `physics.placing`).

Reads `xpos`, `xquat`, `body_rows`, `unplaced` and the Transform store; writes the store
(`sync`) and which rows the store holds (`shown`, `shown_in`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.numeric.rows import run_slice

if TYPE_CHECKING:
    from ecs_tentacles.store import TransformStore

# the poses' scatter by numba when installed (`physics.frame_kernels`); =numpy: numpy
FRAME_KERNELS = OptionalKernels(
    "ecs_tentacles.physics.frame_kernels", "ECS_TENTACLES_PHYSICS_FRAME"
)


class BatchPoses:
    """The pose side of a `Batch`: its rows' poses and where the world reads them."""

    xpos: np.ndarray  # (rows, bodies, 3) the last step's body positions
    xquat: np.ndarray  # (rows, bodies, 4)
    body_rows: np.ndarray  # (rows, bodies) Transform store rows
    # rows whose poses the replay wrote into `shown_in` this frame (None: none)
    shown: np.ndarray | None
    shown_in: TransformStore | None
    _span: slice | None  # `body_rows` as one slice of store rows, when consecutive
    _span_of: np.ndarray | None  # the body_rows the span was found for
    unplaced: np.ndarray | None  # rows shown where the build placed them, not yet written
    placed_in: TransformStore | None  # (`physics.placing`): the store showing them

    def __len__(self) -> int:
        return len(self.body_rows)

    def _follow_shown(self, row: int | None) -> None:
        """`shown` after `append` (row None: a new row, not shown) or `remove(row)`."""
        if self.shown is None:
            return
        if row is None:
            self.shown = np.append(self.shown, False)
        else:
            self.shown = np.delete(self.shown, row)

    def _stepped(self, row: int) -> None:
        """Row `row`'s poses are in `xpos` / `xquat` again (placed or recomputed)."""
        if self.shown is not None:
            self.shown[row] = False

    def _in_store(self, transforms: TransformStore) -> np.ndarray | None:
        """Rows (bool) whose poses are in `transforms` and not in `xpos` / `xquat`: those
        the replay wrote there this frame and those the build only showed; None: none."""
        shown = self.shown
        if shown is not None and (self.shown_in is not transforms or len(shown) != len(self)):
            shown = None
        unplaced = self.unplaced
        if unplaced is None:
            return shown
        return unplaced if shown is None else shown | unplaced

    def sync(self, transforms: TransformStore) -> None:
        """Every row's body poses into the Transform store (one scatter per field, or one
        copy when the rows are consecutive), but those the replay wrote there (`shown`)
        and those the build showed there and never placed (`unplaced`)."""
        span = self.body_span()
        shown = self._in_store(transforms)
        if shown is not None:
            others = np.flatnonzero(~shown)  # the replayed rows are there already
            if span is not None:
                pos, quat = self.store_rows(transforms)
                pos[others], quat[others] = self.xpos[others], self.xquat[others]
            else:
                rows = self.body_rows[others]
                transforms.pos[rows], transforms.quat[rows] = self.xpos[others], self.xquat[others]
            return
        if span is not None:
            transforms.pos[span] = self.xpos.reshape(-1, 3)
            transforms.quat[span] = self.xquat.reshape(-1, 4)
            return
        fast = FRAME_KERNELS.get()
        if fast is not None:  # the same copies, without numpy's indexing
            fast.scatter_poses(self.body_rows, self.xpos, self.xquat, transforms.pos,
                               transforms.quat)  # fmt: skip
        else:
            transforms.pos[self.body_rows] = self.xpos
            transforms.quat[self.body_rows] = self.xquat

    def show(self, transforms: TransformStore | None, rows: np.ndarray | None) -> None:
        """The replay wrote the poses of `rows` (None: of no row) into `transforms` this
        frame and not into `xpos` / `xquat` (one write, not two): `sync` leaves them,
        `poses` and `all_poses` read them there."""
        if transforms is None or rows is None or not len(rows):
            self.shown, self.shown_in = None, None
            return
        self.shown = np.zeros(len(self), dtype=bool)
        self.shown[rows] = True
        self.shown_in = transforms

    def poses(self, row: int) -> tuple[np.ndarray, np.ndarray]:
        """Row `row`'s body poses as shown now, (bodies, 3) and (bodies, 4): its last
        step's (`xpos`, `xquat`), or, replayed (`show`) or not placed yet (`unplaced`), its
        Transform store rows (copies)."""
        if self.shown is not None and self.shown_in is not None and self.shown[row]:
            at = self.body_rows[row]
            return self.shown_in.pos[at], self.shown_in.quat[at]
        if self.unplaced is not None and self.placed_in is not None and self.unplaced[row]:
            at = self.body_rows[row]
            return self.placed_in.pos[at], self.placed_in.quat[at]
        return self.xpos[row].copy(), self.xquat[row].copy()

    def placed_poses(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(len(rows), bodies, 3) and (.., 4): the poses the last step or the placing of
        `rows` left (`xpos` / `xquat`; a row not placed yet: where the build showed it)."""
        unplaced, store = self.unplaced, self.placed_in
        if unplaced is None or store is None:
            return self.xpos[rows], self.xquat[rows]
        late = unplaced[rows]  # (their rows here are never read: no pages for them)
        xpos = np.empty((len(rows), *self.xpos.shape[1:]))
        xquat = np.empty((len(rows), *self.xquat.shape[1:]))
        xpos[~late], xquat[~late] = self.xpos[rows[~late]], self.xquat[rows[~late]]
        at = self.body_rows[rows[late]]
        xpos[late], xquat[late] = store.pos[at], store.quat[at]
        return xpos, xquat

    def all_poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Copies of `xpos` and `xquat` with the replayed rows (`show`) and those not
        placed yet (`unplaced`) as shown: every row's poses as shown now (what a snapshot
        keeps)."""
        xpos, xquat = self.xpos.copy(), self.xquat.copy()
        for held, store in ((self.unplaced, self.placed_in), (self.shown, self.shown_in)):
            if held is not None and store is not None:
                rows = np.flatnonzero(held)
                at = self.body_rows[rows]
                xpos[rows], xquat[rows] = store.pos[at], store.quat[at]
        return xpos, xquat

    def store_rows(self, transforms: TransformStore) -> tuple[np.ndarray, np.ndarray]:
        """The Transform store's pos and quat of this batch's bodies as (rows, bodies, 3)
        and (rows, bodies, 4) views, like `xpos` and `xquat` (only when `body_span` is
        a slice: a uniform crowd's batch)."""
        span = self.body_span()
        if span is None:
            raise ValueError("the batch's bodies are not consecutive rows of the store")
        shape = self.xpos.shape[:2]
        return transforms.pos[span].reshape(*shape, 3), transforms.quat[span].reshape(*shape, 4)

    def body_span(self) -> slice | None:
        """`body_rows` (rows, bodies) as one slice of store rows when they are consecutive
        in row order, else None; found again only when `body_rows` was replaced."""
        rows = self.body_rows
        if self._span_of is not rows:
            self._span = run_slice(rows.ravel())
            self._span_of = rows
        return self._span
